// weft sweep: virtual gonioreflectometer. A parallel light at (theta_i, phi_i), one orthographic
// render of the sample per view direction, radiance coefficients in a CSV.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/job_part.h"
#include "weft/fiber/bake_cache.h"
#include "weft/integrators/gonio.h"
#include "weft/scenes/description.h"

namespace weft::cli {

namespace {

nlohmann::json rgb_json(const Rgb& c) {
  return {c.r, c.g, c.b};
}
Rgb rgb_of(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// What fixes a sweep's bits: the content of every file it reads and every setting but threads.
JobPart sweep_job(const std::string& scene, const SceneDescription& desc, const GonioSettings& g,
                  Shard shard) {
  JobPart p;
  p.command = "sweep";
  p.job = {{"inputs", input_file_hashes(scene_input_files(scene, desc))},
           {"sample", g.sample},
           {"light_zenith_deg", g.light_zenith_deg},
           {"light_azimuth_deg", g.light_azimuth_deg},
           {"irradiance", rgb_json(g.irradiance)},
           {"view_zenith_deg", g.view_zenith_deg},
           {"view_azimuth_deg",
            g.view_azimuth_deg ? nlohmann::json(*g.view_azimuth_deg) : nlohmann::json(nullptr)},
           {"normalize_to", g.normalize_to ? rgb_json(*g.normalize_to) : nlohmann::json(nullptr)},
           {"white_check", g.white_check},
           {"width", g.width},
           {"height", g.height},
           {"spp", g.spp},
           {"max_depth", g.max_depth},
           {"rr_depth", g.rr_depth},
           {"seed", g.seed},
           {"renderer_revision", kPathTracerRevision},
           {"program_version", WEFT_VERSION}};
  // Only when set, so that RGB sweeps' parts keep their identity.
  if (g.spectral) p.job["spectral"] = true;
  p.units_total = gonio_unit_count(g);
  p.shard = shard;
  return p;
}

// The settings a merge needs (normalization, light) back from a job.
GonioSettings sweep_settings(const nlohmann::json& j) {
  GonioSettings g;
  g.light_zenith_deg = j.at("light_zenith_deg").get<double>();
  g.light_azimuth_deg = j.at("light_azimuth_deg").get<double>();
  g.view_zenith_deg = j.at("view_zenith_deg").get<std::vector<double>>();
  if (!j.at("normalize_to").is_null()) g.normalize_to = rgb_of(j.at("normalize_to"));
  return g;
}

// A row: its numbers with their exact bits; the reference unit: beta at normal incidence.
void encode_sweep_units(const GonioResult& r, JobPart& p) {
  for (const auto& row : r.rows) {
    const Rgb w = row.white.value_or(Rgb(0.0));
    p.units[row.view] = {row.view_zenith_deg,
                         row.view_azimuth_deg,
                         row.sum.r,
                         row.sum.g,
                         row.sum.b,
                         row.footprint_px,
                         row.beta.r,
                         row.beta.g,
                         row.beta.b,
                         row.beta_err_rgb.r,
                         row.beta_err_rgb.g,
                         row.beta_err_rgb.b,
                         row.beta_err,
                         row.white ? 1.0 : 0.0,
                         w.r,
                         w.g,
                         w.b};
  }
  if (r.beta_normal && p.units_total > 0) {
    const uint64_t ref = p.units_total - 1;
    if (ref >= p.job.at("view_zenith_deg").size())
      p.units[ref] = {r.beta_normal->r, r.beta_normal->g, r.beta_normal->b};
  }
}

void decode_sweep_unit(uint64_t u, const std::vector<double>& v, const GonioSettings& g,
                       GonioResult& r) {
  if (u == g.view_zenith_deg.size()) {
    if (v.size() != 3) throw Error("", "units", "bad normal-incidence record");
    r.beta_normal = Rgb(v[0], v[1], v[2]);
    return;
  }
  if (v.size() != 17) throw Error("", "units", "bad row record");
  GonioRow row;
  row.view = u;
  row.view_zenith_deg = v[0], row.view_azimuth_deg = v[1];
  row.sum = {v[2], v[3], v[4]};
  row.footprint_px = v[5];
  row.beta = {v[6], v[7], v[8]};
  row.beta_err_rgb = {v[9], v[10], v[11]};
  row.beta_err = v[12];
  if (v[13] != 0) row.white = Rgb(v[14], v[15], v[16]);
  r.rows.push_back(row);
}

// The sweep's result from all its units, as run_gonio gives it in one piece.
GonioResult finish_sweep(const JobPart& all, const GonioSettings& g) {
  GonioResult r;
  r.light_zenith_deg = g.light_zenith_deg;
  r.light_azimuth_deg = g.light_azimuth_deg;
  for (const auto& [u, v] : all.units) decode_sweep_unit(u, v, g, r);  // in unit order
  if (r.rows.size() != g.view_zenith_deg.size())
    throw Error("", "units", "the sweep's views are incomplete");
  normalize_gonio(r, g);
  return r;
}

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

}  // namespace

void add_sweep_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::string scene, output, views, sample, normalize_to;
    double light_zenith = 0, light_azimuth = 0, view_azimuth = 0, irradiance = 1;
    int spp = 0, resolution = 0;  // 0: the scene's
    int threads = GonioSettings{}.threads;
    uint64_t seed = 0;  // used only when --seed is given
    std::string shard;
    bool no_white = false, quiet = false, json = false, resume = false;
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
                 ->check(finite_range(0.0, 89.9));
  auto* la = sub->add_option("--light-azimuth-deg", o->light_azimuth, "light azimuth")
                 ->check(finite_range(-360.0, 360.0));
  sub->add_option("--view-zenith-deg", o->views,
                  "view zeniths: a:b:step, a list a,b,c or one value")
      ->check(non_empty());
  auto* va = sub->add_option("--view-azimuth-deg", o->view_azimuth,
                             "azimuth of the view plane (default: the light's)")
                 ->check(finite_range(-360.0, 360.0));
  sub->add_option("--sample", o->sample,
                  "object to measure (glTF node or mesh name; default: the scene's)")
      ->check(non_empty());
  auto* irr =
      sub->add_option("--irradiance", o->irradiance, "irradiance E of the parallel light, W/m^2")
          ->check(finite_range(1e-12, 1e12));
  sub->add_option(
         "--normalize-to", o->normalize_to,
         "scale beta so that beta(normal incidence, normal view) equals this (value or r,g,b)")
      ->check(non_empty());
  sub->add_flag("--no-white-check", o->no_white, "skip rendering the white Lambert reference");
  sub->add_option("--spp", o->spp, "samples per pixel")->check(CLI::Range(1, 1 << 20));
  sub->add_option("--resolution", o->resolution, "pixels per side of each view")
      ->check(CLI::Range(1, 16384));
  sub->add_option("--threads", o->threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  auto* seed = sub->add_option("--seed", o->seed, "random seed");
  sub->add_option("--shard", o->shard,
                  "K/N: render only shard K of N (views) into a part file for `weft merge`")
      ->check(non_empty());
  sub->add_flag("--resume", o->resume,
                "checkpoint every finished view beside the output and continue from a "
                "checkpoint an earlier run of this sweep left there");
  sub->add_flag("--quiet", o->quiet, "no progress bar and no lights on stderr");
  sub->add_flag("--json", o->json, "also print the rows as JSON on stdout");
  commands.push_back(
      {sub, [o, lz, la, va, irr, seed](const RunLimits& program) {
         const RunLimits limits = quieted(program, o->quiet);
         const SceneDescription desc = load_scene_reporting_warnings(o->scene, {}, o->quiet);
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
         validate_output_paths(
             limits, {{o->output, "--output"}, {checkpoint_path(o->output), "checkpoint"}},
             scene_inputs(o->scene, desc));
         const Shard shard = o->shard.empty() ? Shard{} : parse_shard(o->shard, "--shard");
         const JobPart job = sweep_job(o->scene, desc, g, shard);
         const UnitRange range = shard_units(job.units_total, shard);
         GonioResult done;  // the units of a checkpoint
         std::vector<std::string> warnings;
         if (const auto cp = load_checkpoint(o->output, job, o->resume, warnings))
           for (const auto& [u, v] : cp->units) decode_sweep_unit(u, v, g, done);
         for (const auto& w : warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
         std::vector<size_t> todo;
         for (uint64_t u = range.first; u < range.last; ++u) {
           bool have = u == g.view_zenith_deg.size() && done.beta_normal.has_value();
           for (const auto& row : done.rows) have = have || row.view == u;
           if (!have) todo.push_back(u);
         }
         const bool partial = !shard.whole() || o->resume;
         if (partial) g.units = todo;
         // Each view renders the sample, and the white reference unless --no-white-check.
         check_long_work(
             limits, double(todo.size()) * (g.white_check ? 2 : 1) * g.width * g.height * g.spp,
             kMinSecondsPerPathSample, g.threads, o->scene, "spp",
             "a sweep of " + std::to_string(todo.size()) + " views of " + std::to_string(g.width) +
                 " x " + std::to_string(g.height) + " pixels at " + std::to_string(g.spp) + " spp",
             "0.05 us per path sample per core at least");
         auto part_of = [&](const GonioResult& r, bool checkpoint) {
           JobPart p = job;
           p.checkpoint = checkpoint;
           encode_sweep_units(done, p);
           encode_sweep_units(r, p);
           return p;
         };
         std::function<void(const GonioResult&)> on_unit;
         if (o->resume)
           on_unit = [&](const GonioResult& r) {
             write_job_part(checkpoint_path(o->output), part_of(r, true));
           };
         GonioResult r;
         if (!partial || !todo.empty()) {
           r = run_gonio(desc, g, progress_bar(limits, o->quiet),
                         checked_fiber_table_resolver(limits), on_unit);
           if (const int code = report_render_outcome(r, "sweep")) return code;
         }
         if (!shard.whole()) {
           write_job_part(o->output, part_of(r, false));
           std::filesystem::remove(checkpoint_path(o->output));
           std::printf("views %llu..%llu (shard %u/%u) -> %s\n",
                       static_cast<unsigned long long>(range.first),
                       static_cast<unsigned long long>(range.last), shard.index, shard.count,
                       o->output.c_str());
           return 0;
         }
         // A resumed sweep: the checkpoint's units and the new ones, finished as one.
         if (partial) r = finish_sweep(part_of(r, false), g);
         write_text_atomically(o->output, gonio_csv(r));
         std::filesystem::remove(checkpoint_path(o->output));
         print_sweep_json(r, o->output, o->json);
         return 0;
       }});
}

int merge_sweep(const JobPart& all, const std::string& output, bool json) {
  const GonioResult r = finish_sweep(all, sweep_settings(all.job));
  write_text_atomically(output, gonio_csv(r));
  print_sweep_json(r, output, json);
  return 0;
}

}  // namespace weft::cli
