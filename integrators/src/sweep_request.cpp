#include "weft/integrators/sweep_request.h"

#include <filesystem>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"
#include "weft/integrators/render_settings.h"

namespace weft {
namespace {

nlohmann::json sweep_rgb_json(const Rgb& c) {
  return {c.r, c.g, c.b};
}
Rgb sweep_rgb_of(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// What fixes a sweep's bits: the content of every file it reads and every setting but threads.
JobPart sweep_job(const std::string& scene, const SceneDescription& desc, const GonioSettings& g,
                  Shard shard) {
  JobPart p;
  p.command = "sweep";
  p.job = {
      {"inputs", input_file_hashes(scene_input_files(scene, desc))},
      {"sample", g.sample},
      {"light_zenith_deg", g.light_zenith_deg},
      {"light_azimuth_deg", g.light_azimuth_deg},
      {"irradiance", sweep_rgb_json(g.irradiance)},
      {"view_zenith_deg", g.view_zenith_deg},
      {"view_azimuth_deg",
       g.view_azimuth_deg ? nlohmann::json(*g.view_azimuth_deg) : nlohmann::json(nullptr)},
      {"normalize_to", g.normalize_to ? sweep_rgb_json(*g.normalize_to) : nlohmann::json(nullptr)},
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
  if (!j.at("normalize_to").is_null()) g.normalize_to = sweep_rgb_of(j.at("normalize_to"));
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

// "--normalize-to": one positive value or three.
Rgb parse_sweep_normalization(const std::string& text) {
  const auto v = parse_range(text, "--normalize-to");
  if (v.size() != 1 && v.size() != 3) throw Error("", "--normalize-to", "needs 1 or 3 values");
  for (double x : v)
    if (!(x > 0)) throw Error("", "--normalize-to", "values must be positive");
  return v.size() == 1 ? Rgb(v[0]) : Rgb(v[0], v[1], v[2]);
}

// The scene's sweep with the request's settings over it.
GonioSettings requested_gonio_settings(const SweepRequest& q, const SceneDescription& desc) {
  GonioSettings g = gonio_settings_from(desc);
  if (q.light_zenith_deg)
    g.light_zenith_deg = *q.light_zenith_deg;
  else if (!desc.sweep)
    throw Error("", "--light-zenith-deg", "is required (the scene has no sweep)");
  if (q.light_azimuth_deg) g.light_azimuth_deg = *q.light_azimuth_deg;
  if (!q.view_zenith_deg.empty())
    g.view_zenith_deg = parse_range(q.view_zenith_deg, "--view-zenith-deg");
  if (g.view_zenith_deg.empty())
    throw Error("", "--view-zenith-deg", "is required (the scene's sweep has none)");
  if (q.view_azimuth_deg) g.view_azimuth_deg = *q.view_azimuth_deg;
  if (!q.sample.empty()) g.sample = q.sample;
  if (q.irradiance) g.irradiance = Rgb(*q.irradiance);
  if (!q.normalize_to.empty()) g.normalize_to = parse_sweep_normalization(q.normalize_to);
  if (!q.white_check) g.white_check = false;
  if (q.spp) g.spp = *q.spp;
  if (q.resolution) g.width = g.height = *q.resolution;
  if (q.seed) g.seed = *q.seed;
  g.threads = q.threads;
  return g;
}

// The shard's units that no checkpoint holds; a partial run renders only them.
void plan_sweep_units(SweepPlan& p, const ScenePlanHooks& hooks) {
  const SweepRequest& q = p.request;
  std::vector<std::string> warnings;
  if (const auto cp = load_checkpoint(q.output, p.job, q.resume, warnings))
    for (const auto& [u, v] : cp->units) decode_sweep_unit(u, v, p.settings, p.done);
  for (const auto& w : warnings) hooks.warning(w);
  for (uint64_t u = p.range.first; u < p.range.last; ++u) {
    bool have = u == p.settings.view_zenith_deg.size() && p.done.beta_normal.has_value();
    for (const auto& row : p.done.rows) have = have || row.view == u;
    if (!have) p.todo.push_back(u);
  }
  p.partial = !p.shard.whole() || q.resume;
  if (p.partial) p.settings.units = p.todo;
  p.renders = !p.partial || !p.todo.empty();
}

// A part of the job: the checkpoint's units and those of 'r'.
JobPart sweep_part(const SweepPlan& plan, const GonioResult& r, bool checkpoint) {
  JobPart p = plan.job;
  p.checkpoint = checkpoint;
  encode_sweep_units(plan.done, p);
  encode_sweep_units(r, p);
  return p;
}

}  // namespace

SweepPlan plan_sweep(const SweepRequest& q, const ScenePlanHooks& hooks) {
  SweepPlan p;
  p.request = q;
  p.description = load_scene_description(q.scene, {});
  hooks.scene_loaded(p.description);
  p.settings = requested_gonio_settings(q, p.description);
  validate_output_paths(q.limits,
                        {{q.output, "--output"}, {checkpoint_path(q.output), "checkpoint"}},
                        scene_inputs(q.scene, p.description));
  p.shard = q.shard.empty() ? Shard{} : parse_shard(q.shard, "--shard");
  p.job = sweep_job(q.scene, p.description, p.settings, p.shard);
  p.range = shard_units(p.job.units_total, p.shard);
  plan_sweep_units(p, hooks);
  const GonioSettings& g = p.settings;
  const size_t views = p.todo.size();
  // Each view renders the sample, and the white reference unless --no-white-check.
  check_long_work(q.limits, double(views) * (g.white_check ? 2 : 1) * g.width * g.height * g.spp,
                  kMinSecondsPerPathSample, g.threads, q.scene, "spp",
                  "a sweep of " + std::to_string(views) + " views of " + std::to_string(g.width) +
                      " x " + std::to_string(g.height) + " pixels at " + std::to_string(g.spp) +
                      " spp",
                  "0.05 us per path sample per core at least");
  return p;
}

SweepOutcome run_sweep(const SweepPlan& plan, const SweepHooks& hooks) {
  const std::filesystem::path output = plan.request.output;
  std::function<void(const GonioResult&)> on_unit;
  if (plan.request.resume)
    on_unit = [&](const GonioResult& r) {
      write_job_part(checkpoint_path(output), sweep_part(plan, r, true));
    };
  SweepOutcome out;
  GonioResult r;
  if (plan.renders) {
    r = run_gonio(plan.description, plan.settings, hooks.progress, hooks.fiber_tables, on_unit);
    out.rendered = r;
    if (r.cancelled) return out;
  }
  if (!plan.shard.whole()) {
    write_job_part(output, sweep_part(plan, r, false));
    std::filesystem::remove(checkpoint_path(output));
    return out;
  }
  // A resumed sweep: the checkpoint's units and the new ones, finished as one.
  if (plan.partial) r = finish_sweep(sweep_part(plan, r, false), plan.settings);
  write_text_atomically(output, gonio_csv(r));
  std::filesystem::remove(checkpoint_path(output));
  out.table = std::move(r);
  return out;
}

GonioResult merge_sweep_parts(const JobPart& all, const std::filesystem::path& output) {
  GonioResult r = finish_sweep(all, sweep_settings(all.job));
  write_text_atomically(output, gonio_csv(r));
  return r;
}

}  // namespace weft
