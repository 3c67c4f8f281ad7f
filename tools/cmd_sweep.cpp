// weft sweep: virtual gonioreflectometer. A parallel light at (theta_i, phi_i), one orthographic
// render of the sample per view direction, radiance coefficients in a CSV.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/integrators/gonio.h"
#include "weft/materials/fabric/bake_cache.h"
#include "weft/scenes/description.h"

namespace weft::cli {

void add_sweep_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::string scene, output, views, sample, normalize_to;
    double light_zenith = 0, light_azimuth = 0, view_azimuth = 0, irradiance = 1;
    int spp = 0, resolution = 0;  // 0: the scene's
    int threads = GonioSettings{}.threads;
    uint64_t seed = 0;  // used only when --seed is given
    bool no_white = false, quiet = false, json = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub =
      app.add_subcommand("sweep",
                         "Virtual gonioreflectometer: radiance coefficient of a sample for a "
                         "parallel light and a list of views.\n"
                         "Angles in degrees in the scene's frame. theta_v > 0 lies on the mirror "
                         "side, theta_v < 0 on the light's\n"
                         "side (the paper's Fig. 7). beta = L_sample / (E cos theta_i / pi).");
  sub->add_option("scene", o->scene, "scene description (.json)")->required();
  sub->add_option("-o,--output", o->output, "CSV output")->required();
  auto* lz = sub->add_option("--light-zenith-deg", o->light_zenith, "light zenith")
                 ->check(CLI::Range(0.0, 89.9));
  auto* la = sub->add_option("--light-azimuth-deg", o->light_azimuth, "light azimuth")
                 ->check(CLI::Range(-360.0, 360.0));
  sub->add_option("--view-zenith-deg", o->views,
                  "view zeniths: a:b:step, a list a,b,c or one value");
  auto* va = sub->add_option("--view-azimuth-deg", o->view_azimuth,
                             "azimuth of the view plane (default: the light's)")
                 ->check(CLI::Range(-360.0, 360.0));
  sub->add_option("--sample", o->sample,
                  "object to measure (glTF node or mesh name; default: the scene's)");
  auto* irr =
      sub->add_option("--irradiance", o->irradiance, "irradiance E of the parallel light, W/m^2")
          ->check(CLI::Range(1e-12, 1e12));
  sub->add_option(
      "--normalize-to", o->normalize_to,
      "scale beta so that beta(normal incidence, normal view) equals this (value or r,g,b)");
  sub->add_flag("--no-white-check", o->no_white, "skip rendering the white Lambert reference");
  sub->add_option("--spp", o->spp, "samples per pixel")->check(CLI::Range(1, 1 << 20));
  sub->add_option("--resolution", o->resolution, "pixels per side of each view")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--threads", o->threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  auto* seed = sub->add_option("--seed", o->seed, "random seed");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  sub->add_flag("--json", o->json, "also print the rows as JSON on stdout");
  commands.push_back(
      {sub, [o, lz, la, va, irr, seed] {
         const SceneDescription desc = load_scene_reporting_warnings(o->scene);
         GonioSettings g = gonio_settings_from(desc);
         if (lz->count())
           g.light_zenith_deg = o->light_zenith;
         else if (!desc.sweep)
           throw Error("", "--light-zenith-deg", "is required (the scene has no sweep)");
         if (la->count()) g.light_azimuth_deg = o->light_azimuth;
         if (!o->views.empty()) g.view_zenith_deg = parse_range(o->views, "--view-zenith-deg");
         if (g.view_zenith_deg.empty())
           throw Error("", "--view-zenith-deg", "is required (the scene's sweep has none)");
         if (va->count()) g.view_azimuth_deg = o->view_azimuth;
         if (!o->sample.empty()) g.sample = o->sample;
         if (irr->count()) g.irradiance = Rgb(o->irradiance);
         if (!o->normalize_to.empty()) {
           const auto v = parse_range(o->normalize_to, "--normalize-to");
           if (v.size() != 1 && v.size() != 3)
             throw Error("", "--normalize-to", "needs 1 or 3 values");
           for (double x : v)
             if (!(x > 0)) throw Error("", "--normalize-to", "values must be positive");
           g.normalize_to = v.size() == 1 ? Rgb(v[0]) : Rgb(v[0], v[1], v[2]);
         }
         if (o->no_white) g.white_check = false;
         if (o->spp) g.spp = o->spp;
         if (o->resolution) g.width = g.height = o->resolution;
         if (seed->count()) g.seed = o->seed;
         g.threads = o->threads;
         const auto parent = std::filesystem::path(o->output).parent_path();
         if (!parent.empty() && !std::filesystem::is_directory(parent))
           throw Error(o->output, "", "output directory does not exist");
         const GonioResult r = run_gonio(desc, g, progress_bar(o->quiet), fiber_table_resolver());
         if (const int code = report_render_outcome(r, "sweep")) return code;
         write_text_atomically(o->output, gonio_csv(r));
         if (o->json) {
           nlohmann::json rows = nlohmann::json::array();
           for (const auto& row : r.rows) {
             nlohmann::json j = {{"view_zenith_deg", row.view_zenith_deg},
                                 {"view_azimuth_deg", row.view_azimuth_deg},
                                 {"beta", {row.beta.r, row.beta.g, row.beta.b}},
                                 {"beta_err", row.beta_err},
                                 {"footprint_px", row.footprint_px}};
             if (row.white) j["white"] = {row.white->r, row.white->g, row.white->b};
             if (row.beta_norm)
               j["beta_norm"] = {row.beta_norm->r, row.beta_norm->g, row.beta_norm->b};
             rows.push_back(j);
           }
           nlohmann::json out = {{"output", o->output},
                                 {"light_zenith_deg", r.light_zenith_deg},
                                 {"light_azimuth_deg", r.light_azimuth_deg},
                                 {"rows", rows}};
           if (r.normalization)
             out["normalization"] = {r.normalization->r, r.normalization->g, r.normalization->b};
           std::cout << out.dump(2) << "\n";
         }
         return 0;
       }});
}

}  // namespace weft::cli
