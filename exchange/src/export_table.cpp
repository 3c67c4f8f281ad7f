#include "weft/exchange/export_table.h"

#include <algorithm>
#include <sstream>

#include "weft/core/error.h"

namespace weft {

void check_export_path(const std::filesystem::path& path, const std::string& field) {
  const std::string ext = path.extension().string();
  if (ext != ".bsdf" && ext != ".mbsdf" && ext != ".gltf" && ext != ".glb" && ext != ".html")
    throw Error(
        path.string(), field,
        "unknown format '" + ext + "': the output ends in .bsdf, .mbsdf, .gltf, .glb or .html");
}

std::vector<std::string> export_table_warnings(const TabulatedBsdfTable& table,
                                               const std::string& source) {
  double most = 0;
  for (int b = 0; b < table.grid().bins(); ++b) {
    const auto a = table.directional_albedo(b);
    for (int c = 0; c < table.channels; ++c) most = std::max(most, a.total(c));
  }
  if (!(most > kExportAlbedoWarning)) return {};
  std::ostringstream text;
  text << source << ": the table returns up to " << most
       << " times the light that arrives (directional albedo; a surface returns at most 1, "
          "this check allows up to "
       << kExportAlbedoWarning << " for noise): exported as it is; check the table's scale";
  return {text.str()};
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
    if (ext == ".html") return write_preview_html(table, path, options.name, options.gltf);
    return write_gltf_material(table, path, options.name, options.gltf);
  } catch (const Error& e) {
    // The writers' option errors name only the field: name the output too.
    const std::string what = e.what();
    if (what.rfind(path.string(), 0) == 0) throw;
    throw Error(path.string(), "", what);
  }
}

}  // namespace weft
