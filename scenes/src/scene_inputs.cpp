#include <filesystem>

#include "weft/scenes/description.h"

namespace weft {

std::vector<std::filesystem::path> scene_input_files(const std::string& scene,
                                                     const SceneDescription& d) {
  std::vector<std::filesystem::path> files{scene};
  files.insert(files.end(), d.files.begin(), d.files.end());
  auto add = [&](const MaterialBinding& b) {
    // "weave": a fabric_table's weave table, resolved as its "file".
    for (const char* key : {"file", "spec", "weave"}) {
      if (!b.params.contains(key) || !b.params[key].is_string()) continue;
      std::filesystem::path f = b.params[key].get<std::string>();
      std::error_code ec;
      if (f.is_relative() &&
          (std::string(key) != "spec" || std::filesystem::exists(d.base_dir / f, ec)))
        f = d.base_dir / f;
      // A missing table is the renderer's error to report, with its field.
      if (std::filesystem::is_regular_file(f, ec)) files.push_back(f);
    }
  };
  for (const auto& [key, b] : d.materials) add(b);
  if (d.default_material) add(*d.default_material);
  return files;
}

std::vector<NamedPath> scene_inputs(const std::string& scene, const SceneDescription& d) {
  std::vector<NamedPath> out;
  for (const auto& f : scene_input_files(scene, d))
    out.push_back({f, out.empty() ? "scene description" : "scene's input"});
  // Where fiber_table_resolver keeps the tables it bakes for the scene (bake_cache.h).
  out.push_back({d.base_dir / ".weft-cache", "fiber-table bake cache"});
  return out;
}

}  // namespace weft
