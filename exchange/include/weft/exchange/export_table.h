#pragma once
// weft export's one entry point: the format by the output's extension (.bsdf RGL, .mbsdf MDL,
// .gltf / .glb glTF material, .html a page previewing that material). docs/exchange.md says how
// each renderer loads the file.
#include <filesystem>
#include <string>

#include "weft/exchange/export_report.h"
#include "weft/exchange/gltf_material.h"
#include "weft/exchange/mbsdf.h"
#include "weft/exchange/preview_html.h"
#include "weft/exchange/rgl_bsdf.h"

namespace weft {

struct ExportOptions {
  RglOptions rgl;
  MbsdfOptions mbsdf;
  GltfFitOptions gltf;
  std::string name;  // the material's name and the .bsdf description
};

// Throws weft::Error(path, field, ...) unless the extension is one of the five (commands call it
// before any work).
void check_export_path(const std::filesystem::path& path, const std::string& field);

// What a reader of the exported file should be told of the table itself: a table that returns
// more light than arrives (a directional albedo above kExportAlbedoWarning, a table scaled by
// mistake) is exported as it is, with a warning naming 'source' (the table's file).
inline constexpr double kExportAlbedoWarning = 1.1;  // above 1 by Monte Carlo noise at most
std::vector<std::string> export_table_warnings(const TabulatedBsdfTable& table,
                                               const std::string& source);

ExportReport export_table(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                          const ExportOptions& options);

}  // namespace weft
