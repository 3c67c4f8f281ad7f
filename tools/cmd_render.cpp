// weft render: path-trace a scene description to OpenEXR (+ sRGB PNG preview, + object mask).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/integrators/render_job.h"
#include "weft/materials/fabric/bake_cache.h"
#include "weft/scenes/description.h"

namespace weft::cli {

void add_render_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::string scene, output, preview, mask, mask_object;
    int spp = 0, width = 0, height = 0, max_depth = -1;  // 0, -1: the scene's
    int threads = RenderSettings{}.threads;
    uint64_t seed = 0;  // used only when --seed is given
    bool quiet = false, json = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub =
      app.add_subcommand("render", "Path-trace a scene description (JSON) to an OpenEXR image");
  sub->add_option("scene", o->scene, "scene description (.json)")->required();
  sub->add_option("-o,--output", o->output, "linear RGB OpenEXR output (.exr)")->required();
  sub->add_option("--preview", o->preview, "sRGB PNG preview (.png)");
  sub->add_option("--mask", o->mask, "coverage of --mask-object per pixel (.exr)");
  sub->add_option("--mask-object", o->mask_object, "object (glTF node or mesh name) for --mask");
  sub->add_option("--spp", o->spp, "samples per pixel (default: the scene's)")
      ->check(CLI::Range(1, 1 << 20));
  sub->add_option("--threads", o->threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  auto* seed = sub->add_option("--seed", o->seed, "random seed (default: the scene's)");
  sub->add_option("--width", o->width, "image width (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--height", o->height, "image height (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--max-depth", o->max_depth, "maximum bounces (default: the scene's)")
      ->check(CLI::Range(0, 100000));
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  sub->add_flag("--json", o->json, "print a JSON summary on stdout");
  commands.push_back(
      {sub, [o, seed] {
         if (!o->mask.empty() && o->mask_object.empty())
           throw Error("", "--mask-object", "is required with --mask");
         const SceneDescription desc = load_scene_reporting_warnings(o->scene);
         RenderJob job;
         job.exr = o->output;
         if (!o->preview.empty()) job.png = o->preview;
         if (!o->mask.empty()) job.mask = o->mask;
         job.mask_object = o->mask_object;
         job.settings = render_settings_from(desc);
         if (o->spp) job.settings.spp = o->spp;
         if (o->width) job.settings.width = o->width;
         if (o->height) job.settings.height = o->height;
         if (o->max_depth >= 0) job.settings.max_depth = o->max_depth;
         if (seed->count()) job.settings.seed = o->seed;
         job.settings.threads = o->threads;
         check_memory(render_bytes(job.settings.width, job.settings.height, job.png.has_value(),
                                   job.mask.has_value()),
                      o->scene, "width x height",
                      "a " + std::to_string(job.settings.width) + " x " +
                          std::to_string(job.settings.height) + " render" +
                          (job.mask ? " with a mask" : ""));
         const auto t0 = std::chrono::steady_clock::now();
         const RenderJobResult r =
             render_to_files(desc, job, progress_bar(o->quiet), fiber_table_resolver());
         const double sec =
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
         if (const int code = report_render_outcome(r, "render")) return code;
         if (o->json) {
           nlohmann::json j = {{"output", o->output},
                               {"width", job.settings.width},
                               {"height", job.settings.height},
                               {"spp", job.settings.spp},
                               {"seconds", sec},
                               {"rays", r.rays.total()},
                               {"rays_per_s", r.rays.total() / sec},
                               {"nonfinite_samples", r.nonfinite_samples}};
           std::cout << j.dump(2) << "\n";
         }
         return 0;
       }});
}

}  // namespace weft::cli
