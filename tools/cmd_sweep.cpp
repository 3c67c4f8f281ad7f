// weft sweep: virtual gonioreflectometer. A parallel light at (theta_i, phi_i), one orthographic
// render of the sample per view direction, radiance coefficients in a CSV.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/fiber/bake_cache.h"
#include "weft/integrators/sweep_request.h"
#include "weft/scenes/description.h"

namespace weft::cli {

namespace {

struct SweepCliOptions {
  SweepRequest request;
  bool no_white = false, quiet = false, json = false;
};

void print_sweep_json(const GonioResult& r, const std::string& output, bool json) {
  if (!json) return;
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : r.rows) {
    nlohmann::json j = {{"view_zenith_deg", row.view_zenith_deg},
                        {"view_azimuth_deg", row.view_azimuth_deg},
                        {"beta", {row.beta.r, row.beta.g, row.beta.b}},
                        {"beta_err", row.beta_err},
                        {"footprint_px", row.footprint_px}};
    if (row.white) j["white"] = {row.white->r, row.white->g, row.white->b};
    if (row.beta_norm) j["beta_norm"] = {row.beta_norm->r, row.beta_norm->g, row.beta_norm->b};
    rows.push_back(j);
  }
  nlohmann::json out = {{"output", output},
                        {"light_zenith_deg", r.light_zenith_deg},
                        {"light_azimuth_deg", r.light_azimuth_deg},
                        {"rows", rows}};
  if (r.normalization)
    out["normalization"] = {r.normalization->r, r.normalization->g, r.normalization->b};
  std::cout << out.dump(2) << "\n";
}

int run_sweep_command(const SweepCliOptions& o, const RunLimits& program) {
  SweepRequest request = o.request;
  request.limits = quieted(program, o.quiet);
  request.white_check = !o.no_white;
  const RunLimits& limits = request.limits;
  ScenePlanHooks notices;
  notices.scene_loaded = [&](const SceneDescription& d) { report_scene_loaded(d, o.quiet); };
  notices.warning = [](const std::string& w) {
    std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  };
  const SweepPlan plan = plan_sweep(request, notices);
  SweepHooks hooks;
  // Made only where views are rendered: progress_bar is where a check-only run stops.
  if (plan.renders) {
    hooks.progress = progress_bar(limits, o.quiet);
    hooks.fiber_tables = checked_fiber_table_resolver(limits);
  }
  const SweepOutcome out = run_sweep(plan, hooks);
  if (const int code = report_render_outcome(out.rendered, "sweep")) return code;
  if (!out.table) {
    std::printf("views %llu..%llu (shard %u/%u) -> %s\n",
                static_cast<unsigned long long>(plan.range.first),
                static_cast<unsigned long long>(plan.range.last), plan.shard.index,
                plan.shard.count, request.output.c_str());
    return 0;
  }
  print_sweep_json(*out.table, request.output, o.json);
  return 0;
}

// The light, the views and the sample.
void add_sweep_geometry(CLI::App* sub, SweepRequest& q) {
  sub->add_option("--light-zenith-deg", q.light_zenith_deg, "light zenith")
      ->check(finite_range(0.0, 89.9));
  sub->add_option("--light-azimuth-deg", q.light_azimuth_deg, "light azimuth")
      ->check(finite_range(-360.0, 360.0));
  sub->add_option("--view-zenith-deg", q.view_zenith_deg,
                  "view zeniths: a:b:step, a list a,b,c or one value")
      ->check(non_empty());
  sub->add_option("--view-azimuth-deg", q.view_azimuth_deg,
                  "azimuth of the view plane (default: the light's)")
      ->check(finite_range(-360.0, 360.0));
  sub->add_option("--sample", q.sample,
                  "object to measure (glTF node or mesh name; default: the scene's)")
      ->check(non_empty());
  sub->add_option("--irradiance", q.irradiance, "irradiance E of the parallel light, W/m^2")
      ->check(finite_range(1e-12, 1e12));
  sub->add_option(
         "--normalize-to", q.normalize_to,
         "scale beta so that beta(normal incidence, normal view) equals this (value or r,g,b)")
      ->check(non_empty());
}

// The renders, and how the run is split and resumed.
void add_sweep_run(CLI::App* sub, SweepRequest& q) {
  sub->add_option("--spp", q.spp, "samples per pixel")->check(CLI::Range(1, 1 << 20));
  sub->add_option("--resolution", q.resolution, "pixels per side of each view")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--threads", q.threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  sub->add_option("--seed", q.seed, "random seed");
  sub->add_option("--shard", q.shard,
                  "K/N: render only shard K of N (views) into a part file for `weft merge`")
      ->check(non_empty());
  sub->add_flag("--resume", q.resume,
                "checkpoint every finished view beside the output and continue from a "
                "checkpoint an earlier run of this sweep left there");
}

}  // namespace

void add_sweep_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<SweepCliOptions>();
  auto* sub =
      app.add_subcommand("sweep",
                         "Virtual gonioreflectometer: radiance coefficient of a sample for a "
                         "parallel light and a list of views.\n"
                         "Angles in degrees in the scene's frame. theta_v > 0 lies on the mirror "
                         "side, theta_v < 0 on the light's\n"
                         "side (the paper's Fig. 7). beta = L_sample / (E cos theta_i / pi).");
  sub->add_option("scene", o->request.scene, "scene description (.json)")->required();
  sub->add_option("-o,--output", o->request.output, "CSV output")->required();
  add_sweep_geometry(sub, o->request);
  sub->add_flag("--no-white-check", o->no_white, "skip rendering the white Lambert reference");
  add_sweep_run(sub, o->request);
  sub->add_flag("--quiet", o->quiet, "no progress bar and no lights on stderr");
  sub->add_flag("--json", o->json, "also print the rows as JSON on stdout");
  commands.push_back({sub, [o](const RunLimits& l) { return run_sweep_command(*o, l); }});
}

int merge_sweep(const JobPart& all, const std::string& output, bool json) {
  print_sweep_json(merge_sweep_parts(all, output), output, json);
  return 0;
}

}  // namespace weft::cli
