#pragma once
// weft export's one entry point: the format by the output's extension (.bsdf RGL, .mbsdf MDL,
// .gltf / .glb glTF material). docs/exchange.md says how each renderer loads the file.
#include <filesystem>
#include <string>

#include "weft/exchange/export_report.h"
#include "weft/exchange/gltf_material.h"
#include "weft/exchange/mbsdf.h"
#include "weft/exchange/rgl_bsdf.h"

namespace weft {

struct ExportOptions {
  RglOptions rgl;
  MbsdfOptions mbsdf;
  GltfFitOptions gltf;
  std::string name;  // the material's name and the .bsdf description
};

// Throws weft::Error(path, field, ...) unless the extension is one of the four (commands call it
// before any work).
void check_export_path(const std::filesystem::path& path, const std::string& field);

ExportReport export_table(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                          const ExportOptions& options);

}  // namespace weft
