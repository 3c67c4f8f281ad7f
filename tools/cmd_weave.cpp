// weft weave: generate a woven patch (glTF) of yarn tubes.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/scenes/weave.h"

namespace weft::cli {

void add_weave_command(CLI::App& app, Commands& commands) {
  struct Options {
    WeaveParams p;
    std::string output;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub =
      app.add_subcommand("weave", "Generate a woven patch of yarn tubes as glTF (y up, metres)");
  sub->add_option("--pattern", o->p.pattern, "weave pattern (plain)")->capture_default_str();
  sub->add_option("--yarns", o->p.yarns, "yarns per direction")->capture_default_str();
  sub->add_option("--yarn-radius-mm", o->p.yarn_radius_mm, "yarn radius, mm")
      ->capture_default_str();
  sub->add_option("--spacing-mm", o->p.spacing_mm, "distance between parallel yarns, mm")
      ->capture_default_str();
  sub->add_option("--segments", o->p.segments, "segments along each yarn")->capture_default_str();
  sub->add_option("--sides", o->p.sides, "segments around each yarn")->capture_default_str();
  sub->add_option("--amplitude-mm", o->p.amplitude_mm,
                  "centre-line amplitude, mm (default: the yarn radius)");
  sub->add_option("-o,--output", o->output, "output (.gltf with embedded buffer, or .glb)")
      ->required();
  sub->add_flag("--json", o->json, "print a JSON summary");
  commands.push_back(
      {sub, [o] {
         const auto meshes = make_weave(o->p);
         size_t tris = 0, verts = 0;
         for (const auto& m : meshes) tris += m.triangle_count(), verts += m.vertex_count();
         write_weave(o->output, o->p);
         if (o->json) {
           std::cout << nlohmann::json(
                            {{"output", o->output}, {"triangles", tris}, {"vertices", verts}})
                            .dump(2)
                     << "\n";
         } else {
           std::printf("%s: %zu triangles, %zu vertices\n", o->output.c_str(), tris, verts);
         }
         return 0;
       }});
}

}  // namespace weft::cli
