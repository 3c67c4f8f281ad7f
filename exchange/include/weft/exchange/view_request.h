#pragma once
// weft view TABLE.exr -o PAGE.html: one offline page of any table (docs/exchange.md), as a
// request, a plan and a run. It is the page weft export -o X.html writes (preview_html.h), with
// the incidence of the in-plane curves chosen on the page; for a fiber table it holds the curves
// alone, because the glTF material is a cloth surface's fit and a fiber table's directions are in
// the frame of a point on a fiber, so a cushion in that material would show no fiber's look.
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/install_paths.h"
#include "weft/core/run_limits.h"
#include "weft/exchange/export_report.h"
#include "weft/exchange/preview_html.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct ViewRequest {
  std::string table;   // a Weft table (.exr), fabric or fiber
  std::string output;  // the page (.html)
  std::string name;    // the title and the material's name; "" = the table's file name
  // Where the viewer's scripts are looked for (install_paths.h).
  std::vector<std::filesystem::path> viewer_roots = bundled_data_roots();
  RunLimits limits;
};

struct ViewPlan {
  ViewRequest request;
  TabulatedBsdfTable table;
  std::string name;
  PreviewPage shows;
  std::vector<std::string> warnings;  // what a reader should know of the table (export_table.h)
};

// Reads and checks everything before any work: the output's name (.html, field "--output"), the
// output guard (not the table, in an existing folder), the table (weft::Error naming the file when
// it is missing or not a table) and the viewer's scripts (three.js only when the page shows the
// material). Nothing is written.
ViewPlan plan_view(const ViewRequest& request);

// Writes the page atomically; what it holds, as weft export reports it.
ExportReport run_view(const ViewPlan& plan);

}  // namespace weft
