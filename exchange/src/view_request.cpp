// weft view (view_request.h): the preview page of any table.
#include "weft/exchange/view_request.h"

#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/exchange/export_table.h"

namespace weft {

ViewPlan plan_view(const ViewRequest& request) {
  ViewPlan plan;
  plan.request = request;
  const std::filesystem::path output = request.output;
  if (output.extension() != ".html")
    throw Error(request.output, "--output", "the page's name ends in .html");
  validate_output_paths(request.limits, {{output, "--output"}}, {{request.table, "table"}});
  plan.table = TabulatedBsdfTable::read_exr(request.table);
  plan.name =
      request.name.empty() ? std::filesystem::path(request.table).stem().string() : request.name;
  if (plan.table.kind == "fiber") {
    plan.shows.material = false;
    plan.shows.notes.push_back(
        "a fiber table (kind \"fiber\"): its directions are in the frame of a point on a fiber, so "
        "the page shows its in-plane curves in that frame and no glTF material on a cloth; weft "
        "export " +
        request.table + " -o X.html fits and shows one anyway");
  }
  // The viewer's files are read again when the page is written; here a missing one stops the
  // command before the fit.
  if (plan.shows.material) load_viewer_modules(request.viewer_roots);
  load_inplane_script(request.viewer_roots);
  plan.warnings = export_table_warnings(plan.table, request.table);
  return plan;
}

ExportReport run_view(const ViewPlan& plan) {
  work_starts(plan.request.limits);
  try {
    return write_preview_html(plan.table, plan.request.output, plan.name, {},
                              plan.request.viewer_roots, plan.shows);
  } catch (const Error& e) {
    // The writer's own errors name only a field: name the page too.
    const std::string what = e.what();
    if (what.rfind(plan.request.output, 0) == 0) throw;
    throw Error(plan.request.output, "", what);
  }
}

}  // namespace weft
