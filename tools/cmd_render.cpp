// weft render: path-trace a scene description to OpenEXR (+ sRGB PNG preview, + object mask,
// + albedo and normal passes).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/fiber/bake_cache.h"
#include "weft/integrators/render_job.h"
#include "weft/scenes/description.h"

namespace weft::cli {
namespace {

// "--crop x0,x1,y0,y1": four whole pixel numbers.
PixelWindow parse_crop(const std::string& text) {
  std::vector<int> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    const auto n = finite_number(part);
    if (!n || *n != std::floor(*n) || *n < 0 || *n > 16384)
      throw Error("", "--crop", "'" + part + "' is not a pixel number (0 to 16384)");
    v.push_back(static_cast<int>(*n));
  }
  if (v.size() != 4) throw Error("", "--crop", "must be x0,x1,y0,y1, got '" + text + "'");
  return {v[0], v[1], v[2], v[3]};
}

// "OUT.exr" -> "OUT.<pass>.exr".
std::filesystem::path pass_path(const std::filesystem::path& exr, const std::string& pass) {
  std::filesystem::path p = exr;
  p.replace_extension("." + pass + ".exr");
  return p;
}

}  // namespace

void add_render_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::string scene, output, preview, mask, mask_object, camera, crop, aov;
    std::vector<std::string> defines;
    int spp = 0, width = 0, height = 0, max_depth = -1;  // 0, -1: the scene's
    int threads = RenderSettings{}.threads;
    uint64_t seed = 0;  // used only when --seed is given
    double exposure_ev = 0, time_limit_s = 0;
    bool quiet = false, json = false, spectral = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "render", "Path-trace a scene description (JSON) to an image (EXR, PNG, HDR)");
  sub->add_option("scene", o->scene, "scene description (.json)")->required();
  sub->add_option("-o,--output", o->output,
                  "output image by its extension: .exr (linear RGB OpenEXR with the render's "
                  "metadata), .png (8-bit sRGB as --preview, --exposure applied) or .hdr "
                  "(Radiance RGBE, linear)")
      ->required();
  sub->add_option("-D,--define", o->defines,
                  "KEY=VALUE: set a value of the description, KEY its JSON path "
                  "(materials.seat.params.reflectance=0.5, lights[0].irradiance=[3,3,3], "
                  "render.spp=64); repeatable, docs/scenes.md")
      ->allow_extra_args(false);
  sub->add_option("--camera", o->camera,
                  "glTF camera by name or index (0, 1, ...) instead of the description's")
      ->check(non_empty());
  sub->add_option("--crop", o->crop,
                  "x0,x1,y0,y1: render only pixels x0 <= x < x1, y0 <= y < y1 (same pixels as "
                  "the whole render; the EXR's data window)")
      ->check(non_empty());
  sub->add_option("--preview", o->preview, "sRGB PNG preview (.png)")->check(non_empty());
  sub->add_option("--exposure", o->exposure_ev,
                  "preview exposure in stops: the PNG shows linear values x 2^EV, clipped to "
                  "[0, 1], sRGB-encoded (no other tone mapping; the EXR is unchanged)")
      ->check(finite_range(-64.0, 64.0));
  sub->add_option("--time-limit", o->time_limit_s,
                  "seconds: stop after the whole pass (1 sample per pixel) that ends past it and "
                  "write the mean of the passes done (weft:spp in the EXR)")
      ->check(finite_range(1e-9, 1e9));
  sub->add_option("--aov", o->aov,
                  "albedo,normal: extra passes of the first surface seen, written to "
                  "OUTPUT.albedo.exr and OUTPUT.normal.exr")
      ->check(non_empty());
  sub->add_option("--mask", o->mask, "coverage of --mask-object per pixel (.exr)")
      ->check(non_empty());
  sub->add_option("--mask-object", o->mask_object, "object (glTF node or mesh name) for --mask")
      ->check(non_empty());
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
  sub->add_flag("--spectral", o->spectral,
                "transport light per wavelength band (33 bands; every material spectral, every "
                "light grey), as the scene's render.spectral");
  sub->add_flag("--quiet", o->quiet,
                "nothing on stderr but warnings and errors (no lights, progress or summary)");
  sub->add_flag("--json", o->json, "print a JSON summary on stdout");
  commands.push_back(
      {sub, [o, seed](const RunLimits& program) {
         const RunLimits limits = quieted(program, o->quiet);
         if (!o->mask.empty() && o->mask_object.empty())
           throw Error("", "--mask-object", "is required with --mask");
         std::vector<SceneOverride> overrides;
         for (const auto& d : o->defines) overrides.push_back(parse_scene_override(d));
         SceneDescription desc = load_scene_reporting_warnings(o->scene, overrides, o->quiet);
         RenderJob job;
         job.exr = o->output;
         if (!o->preview.empty()) job.png = o->preview;
         if (!o->mask.empty()) job.mask = o->mask;
         job.mask_object = o->mask_object;
         if (!o->aov.empty()) {
           std::stringstream ss(o->aov);
           std::string pass;
           while (std::getline(ss, pass, ',')) {
             if (pass == "albedo")
               job.albedo = pass_path(job.exr, pass);
             else if (pass == "normal")
               job.normal = pass_path(job.exr, pass);
             else
               throw Error("", "--aov", "unknown pass '" + pass + "' (valid: albedo, normal)");
           }
         }
         if (!o->camera.empty()) {
           const NamedCamera c = select_camera(desc, o->camera);
           desc.camera = c.camera;
           job.camera_name = c.name.empty() ? "glTF camera " + o->camera : c.name;
         }
         job.preview_exposure = std::exp2(o->exposure_ev);
         job.settings = render_settings_from(desc);
         if (o->spp) job.settings.spp = o->spp;
         if (o->width) job.settings.width = o->width;
         if (o->height) job.settings.height = o->height;
         if (o->max_depth >= 0) job.settings.max_depth = o->max_depth;
         if (seed->count()) job.settings.seed = o->seed;
         if (o->spectral) job.settings.spectral = true;
         if (o->time_limit_s > 0) job.settings.time_limit_s = o->time_limit_s;
         if (!o->crop.empty()) {
           job.settings.crop = parse_crop(o->crop);
           check_crop(*job.settings.crop, job.settings.width, job.settings.height, "", "--crop");
         }
         job.settings.threads = o->threads;
         std::vector<NamedPath> outputs = {{job.exr, "--output"}};
         if (job.png) outputs.push_back({*job.png, "--preview"});
         if (job.mask) outputs.push_back({*job.mask, "--mask"});
         if (job.albedo) outputs.push_back({*job.albedo, "--aov albedo"});
         if (job.normal) outputs.push_back({*job.normal, "--aov normal"});
         validate_output_paths(limits, outputs, scene_inputs(o->scene, desc));
         check_memory(limits,
                      render_bytes(job.settings.width, job.settings.height, job.png.has_value(),
                                   job.mask.has_value()),
                      o->scene, "width x height",
                      "a " + std::to_string(job.settings.width) + " x " +
                          std::to_string(job.settings.height) + " render" +
                          (job.mask ? " with a mask" : ""));
         // A time limit bounds the work itself.
         if (!(job.settings.time_limit_s > 0)) {
           const auto& c = job.settings.crop;
           const double pixels = c ? double(c->width()) * c->height()
                                   : double(job.settings.width) * job.settings.height;
           check_long_work(limits, pixels * job.settings.spp, kMinSecondsPerPathSample,
                           job.settings.threads, o->scene, "spp",
                           "a render of " + std::to_string(int64_t(pixels)) + " pixels at " +
                               std::to_string(job.settings.spp) + " spp",
                           "0.05 us per path sample per core at least");
         }
         const auto t0 = std::chrono::steady_clock::now();
         const RenderJobResult r = render_to_files(desc, job, progress_bar(limits, o->quiet),
                                                   checked_fiber_table_resolver(limits));
         const double sec = seconds_since(t0);
         if (const int code = report_render_outcome(r, "render")) return code;
         const double rays_per_s = sec > 0 ? r.rays.total() / sec : 0;
         if (!o->quiet) {
           std::fprintf(stderr,
                        "weft: render: %d of %d samples per pixel, %.3g rays in %.3g s (%s)\n",
                        r.spp_done, job.settings.spp, double(r.rays.total()), sec,
                        format_rate(rays_per_s, "rays").c_str());
         }
         if (o->json) {
           nlohmann::json j = {{"output", o->output},
                               {"width", job.settings.width},
                               {"height", job.settings.height},
                               {"spp", job.settings.spp},
                               {"spp_done", r.spp_done},
                               {"seconds", sec},
                               {"rays", r.rays.total()},
                               {"rays_per_s", rays_per_s},
                               {"nonfinite_samples", r.nonfinite_samples}};
           if (job.settings.crop) {
             const PixelWindow& w = *job.settings.crop;
             j["crop"] = {w.x0, w.x1, w.y0, w.y1};
           }
           if (!r.weave_levels.empty()) j["weave_levels"] = weave_levels_json(r.weave_levels);
           if (job.albedo) j["albedo"] = job.albedo->string();
           if (job.normal) j["normal"] = job.normal->string();
           std::cout << j.dump(2) << "\n";
         }
         return 0;
       }});
}

}  // namespace weft::cli
