#include "weft/exchange/export_table.h"

#include "weft/core/error.h"

namespace weft {

void check_export_path(const std::filesystem::path& path, const std::string& field) {
  const std::string ext = path.extension().string();
  if (ext != ".bsdf" && ext != ".mbsdf" && ext != ".gltf" && ext != ".glb")
    throw Error(path.string(), field,
                "unknown format '" + ext + "': the output ends in .bsdf, .mbsdf, .gltf or .glb");
}

ExportReport export_table(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                          const ExportOptions& options) {
  check_export_path(path, "output");
  table.validate(path.string());
  const std::string ext = path.extension().string();
  try {
    if (ext == ".bsdf") {
      RglOptions rgl = options.rgl;
      if (rgl.description.empty()) rgl.description = "Weft table " + options.name;
      return write_rgl_bsdf(table, path, rgl);
    }
    if (ext == ".mbsdf") return write_mbsdf(table, path, options.mbsdf);
    return write_gltf_material(table, path, options.name, options.gltf);
  } catch (const Error& e) {
    // The writers' option errors name only the field: name the output too.
    const std::string what = e.what();
    if (what.rfind(path.string(), 0) == 0) throw;
    throw Error(path.string(), "", what);
  }
}

}  // namespace weft
