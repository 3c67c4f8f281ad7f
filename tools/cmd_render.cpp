// weft render: path-trace a scene description to OpenEXR (+ sRGB PNG preview, + object mask,
// + albedo and normal passes).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/clock.h"
#include "weft/core/progress.h"
#include "weft/fiber/bake_cache.h"
#include "weft/integrators/render_request.h"
#include "weft/scenes/description.h"

namespace weft::cli {
namespace {

struct RenderCliOptions {
  RenderRequest request;
  bool quiet = false, json = false;
};

// The summary of a finished render: stderr unless quiet, JSON on stdout when asked.
void print_render_summary(const RenderCliOptions& o, const RenderJob& job, const RenderJobResult& r,
                          double sec) {
  const double rays_per_s = sec > 0 ? r.rays.total() / sec : 0;
  if (!o.quiet) {
    std::fprintf(stderr, "weft: render: %d of %d samples per pixel, %.3g rays in %.3g s (%s)\n",
                 r.spp_done, job.settings.spp, double(r.rays.total()), sec,
                 format_rate(rays_per_s, "rays").c_str());
  }
  if (!o.json) return;
  nlohmann::json j = {{"output", o.request.output},
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

int run_render(const RenderCliOptions& o, const RunLimits& program) {
  RenderRequest request = o.request;
  request.limits = quieted(program, o.quiet);
  const RunLimits& limits = request.limits;
  ScenePlanHooks hooks;
  hooks.scene_loaded = [&](const SceneDescription& d) { report_scene_loaded(d, o.quiet); };
  hooks.warning = [](const std::string& w) {
    std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  };
  const RenderPlan plan = plan_render(request, hooks);
  const auto t0 = std::chrono::steady_clock::now();
  const RenderJobResult r =
      render_to_files(plan.description, plan.job, progress_bar(limits, o.quiet),
                      checked_fiber_table_resolver(limits));
  const double sec = seconds_since(t0);
  if (const int code = report_render_outcome(r, "render")) return code;
  print_render_summary(o, plan.job, r, sec);
  return 0;
}

// The scene, its overrides and the files written.
void add_render_files(CLI::App* sub, RenderRequest& q) {
  sub->add_option("scene", q.scene, "scene description (.json)")->required();
  sub->add_option("-o,--output", q.output,
                  "output image by its extension: .exr (linear RGB OpenEXR with the render's "
                  "metadata), .png (8-bit sRGB as --preview, --exposure applied) or .hdr "
                  "(Radiance RGBE, linear)")
      ->required();
  sub->add_option("-D,--define", q.defines,
                  "KEY=VALUE: set a value of the description, KEY its JSON path "
                  "(materials.seat.params.reflectance=0.5, lights[0].irradiance=[3,3,3], "
                  "render.spp=64); repeatable, docs/scenes.md")
      ->allow_extra_args(false);
  sub->add_option("--camera", q.camera,
                  "glTF camera by name or index (0, 1, ...) instead of the description's")
      ->check(non_empty());
  sub->add_option("--crop", q.crop,
                  "x0,x1,y0,y1: render only pixels x0 <= x < x1, y0 <= y < y1 (same pixels as "
                  "the whole render; the EXR's data window)")
      ->check(non_empty());
  sub->add_option("--preview", q.preview, "sRGB PNG preview (.png)")->check(non_empty());
  sub->add_option("--exposure", q.exposure_ev,
                  "preview exposure in stops: the PNG shows linear values x 2^EV, clipped to "
                  "[0, 1], sRGB-encoded (no other tone mapping; the EXR is unchanged)")
      ->check(finite_range(-64.0, 64.0));
  sub->add_option("--time-limit", q.time_limit_s,
                  "seconds: stop after the whole pass (1 sample per pixel) that ends past it and "
                  "write the mean of the passes done (weft:spp in the EXR)")
      ->check(finite_range(1e-9, 1e9));
  sub->add_option("--aov", q.aov,
                  "albedo,normal: extra passes of the first surface seen, written to "
                  "OUTPUT.albedo.exr and OUTPUT.normal.exr")
      ->check(non_empty());
  sub->add_option("--mask", q.mask, "coverage of --mask-object per pixel (.exr)")
      ->check(non_empty());
  sub->add_option("--mask-object", q.mask_object, "object (glTF node or mesh name) for --mask")
      ->check(non_empty());
}

// The render settings over the scene's.
void add_render_settings(CLI::App* sub, RenderRequest& q) {
  sub->add_option("--spp", q.spp, "samples per pixel (default: the scene's)")
      ->check(CLI::Range(1, 1 << 20));
  sub->add_option("--threads", q.threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  sub->add_option("--seed", q.seed, "random seed (default: the scene's)");
  sub->add_option("--width", q.width, "image width (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--height", q.height, "image height (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--max-depth", q.max_depth, "maximum bounces (default: the scene's)")
      ->check(CLI::Range(0, 100000));
  sub->add_flag("--spectral", q.spectral,
                "transport light per wavelength band (33 bands; every material spectral, every "
                "light grey), as the scene's render.spectral");
}

}  // namespace

void add_render_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<RenderCliOptions>();
  auto* sub = app.add_subcommand(
      "render", "Path-trace a scene description (JSON) to an image (EXR, PNG, HDR)");
  add_render_files(sub, o->request);
  add_render_settings(sub, o->request);
  sub->add_flag("--quiet", o->quiet,
                "nothing on stderr but warnings and errors (no lights, progress or summary)");
  sub->add_flag("--json", o->json, "print a JSON summary on stdout");
  commands.push_back({sub, [o](const RunLimits& l) { return run_render(*o, l); }});
}

}  // namespace weft::cli
