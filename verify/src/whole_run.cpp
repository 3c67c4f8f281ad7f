// weft verify's whole run from its plan: inputs, a shard's part, or the report (whole_run.h).
#include "weft/verify/whole_run.h"

#include <algorithm>
#include <chrono>

#include "common.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/fabric/fabric_colour.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/bake_cache.h"
#include "weft/verify/fit_models.h"

namespace weft {

namespace {

// The spectral fiber table through the bake cache (./.weft-cache, bake_cache.h): shards of a job
// that need it at once bake it once, and the merge reuses it. Returns false when interrupted.
bool fiber_from_cache(const VerifyPlan& p, VerifyInputs& in, const VerifyHooks& hooks) {
  const VerifySettings& s = p.settings;
  const FiberTableBakeOptions b =
      verify_bake_options(p.spec, s.resolution, s.fiber_photons_per_band, s.seed, s.threads, false);
  std::filesystem::path file;
  try {
    file = cached_fiber_table(".weft-cache", p.spec, b, hooks.progress);
  } catch (const Error&) {
    if (hooks.interrupted()) return false;
    throw;
  }
  in.fiber = TabulatedBsdfTable::read_exr(file);
  in.volume_albedo = volume_albedo_of(in.fiber, file.string());
  return true;
}

// The fiber (the given table, or the spec's bake) and the classic baseline's roughness, index and
// colour. Returns false when interrupted.
bool fiber_inputs(const VerifyPlan& p, VerifyInputs& in, const VerifyHooks& hooks) {
  const auto t0 = std::chrono::steady_clock::now();
  if (p.fiber_table) {
    classic_from_table(p.request.fiber, *p.fiber_table, p.classic_albedo, p.settings, in);
    in.fiber = *p.fiber_table;
    in.seconds["classic_from_table"] = seconds_since(t0);
    return true;
  }
  if (!fiber_from_cache(p, in, hooks)) return false;
  in.seconds["fiber_bake"] = seconds_since(t0);
  in.classic_distribution = {p.spec.roughness_distribution, p.spec.roughness_alpha};
  in.classic_ior = p.spec.host_n[kNumBands / 2];  // 550 nm
  if (p.classic_albedo) {
    in.classic_diffuse = p.classic_albedo;
    in.classic_source = "--classic-albedo; the spec's roughness and index at 550 nm";
  }
  return true;
}

// The colour match of a plan with a colour (docs/colour.md): readings of the computed model's
// ray trace at the plan's settings (the first batch's seed, the normal's incident bin), each on
// the spec's spectral fiber table through the bake cache, which the run then reuses. Nothing when
// interrupted.
std::optional<FabricColourMatch> verify_colour_match(const VerifyPlan& p, const WovenSample& sample,
                                                     const VerifyHooks& hooks) {
  const VerifySettings& s = p.settings;
  const std::vector<VerifyTrace> traces = verify_traces(s);
  const auto computed = std::find_if(traces.begin(), traces.end(),
                                     [](const VerifyTrace& t) { return t.model == "computed"; });
  const nlohmann::json inputs = {{"verify", quality_name(s.quality)},
                                 {"resolution", s.resolution},
                                 {"fiber_photons_per_band", s.fiber_photons_per_band},
                                 {"particles_per_bin", computed->options.particles_per_bin},
                                 {"seed", computed->options.seed},
                                 {"sample", woven_sample_identity(sample)}};
  try {
    FabricColourMatch m = cached_colour_match(
        inputs, p.spec, *p.colour, [&](const FiberSpec& spec) -> std::optional<Spectrum> {
          const FiberTableBakeOptions b = verify_bake_options(
              spec, s.resolution, s.fiber_photons_per_band, s.seed, s.threads, false);
          const TabulatedBsdfTable fiber = TabulatedBsdfTable::read_exr(
              cached_fiber_table(".weft-cache", spec, b, hooks.progress));
          return raytrace_d8_reading(sample, fiber, computed->options, hooks.progress);
        });
    if (m.match.cancelled) return std::nullopt;
    return m;
  } catch (const Error&) {
    if (hooks.interrupted()) return std::nullopt;
    throw;
  }
}

// The sample as the report names it, with what the generator chose (the densest packing that
// fits) and what does not apply to it.
std::string sample_name(const WeaveSummary& s) {
  std::string name = s.source + " (" + s.detail + ")";
  for (const std::string& note : s.notes) name += "; " + note;
  if (s.nonwoven)
    name += "; the paper's summation is not applicable to a nonwoven (no warp and weft): not run";
  return name;
}

// A shard's units of the ray traces into a part file at the request's output.
VerifyOutcome run_shard(const VerifyPlan& p, const WovenSample& sample, const VerifyInputs& in,
                        const JobPart& job, const VerifyHooks& hooks) {
  VerifyOutcome out;
  const uint64_t bins = DirectionGrid{p.settings.resolution}.bins();
  const UnitRange range = shard_units(job.units_total, job.shard);
  const std::vector<VerifyTrace> traces = verify_traces(p.settings);
  std::optional<ClassicFiber> classic;
  JobPart part = job;
  for (size_t t = 0; t < traces.size(); ++t) {
    const uint64_t first = std::max(range.first, t * bins),
                   last = std::min(range.last, (t + 1) * bins);
    if (first >= last) continue;
    if (traces[t].model == "classic" && !classic)
      classic = verify_classic_fiber(in, p.settings, hooks.progress);
    FabricRaytraceOptions r = traces[t].options;
    r.first_bin = static_cast<int>(first - t * bins);
    r.bin_count = static_cast<int>(last - first);
    const FabricRaytraceResult res = raytrace_fabric_table(
        sample, traces[t].model == "classic" ? classic->table : in.fiber, r, hooks.progress);
    if (res.cancelled) {
      out.cancelled = true;
      return out;
    }
    for (uint64_t u = first; u < last; ++u) encode_fabric_bin(res, u - t * bins, part.units[u]);
  }
  write_job_part(p.request.output, part);
  part.units.clear();  // written; the outcome names the job and the range
  out.part = std::move(part);
  out.part_units = range;
  return out;
}

// A merge's ray traces, from every unit of the sharded job.
VerifyTraced traced_from_parts(const JobPart& all, const VerifySettings& s) {
  VerifyTraced traced;
  const uint64_t bins = DirectionGrid{s.resolution}.bins();
  const std::vector<VerifyTrace> traces = verify_traces(s);
  for (size_t t = 0; t < traces.size(); ++t) {
    const auto it = all.units.find(t * bins);
    if (it == all.units.end()) throw Error("", "parts", "a ray trace's first bin is missing");
    traced[{traces[t].model, traces[t].batch}] = assemble_fabric_bins(
        all.units, t * bins, bins, s.resolution, fabric_bin_channels(it->second, bins));
  }
  return traced;
}

// The summation, the ray traces (or the merge's), run_verify and the fit, then the report folder.
VerifyOutcome run_report(const VerifyPlan& p, const WovenSample& sample, VerifyInputs& in,
                         const VerifyHooks& hooks, const JobPart* all) {
  const VerifySettings& s = p.settings;
  VerifyOutcome out;
  auto t0 = std::chrono::steady_clock::now();
  // The paper's summation averages a warp and a weft fiber: a nonwoven mat has neither (the
  // report then has no summation model; its sample line says why).
  if (!sample.summary.nonwoven) {
    in.summation = sum_fabric_table(
        in.fiber, verify_summation_options(s.resolution, s.summation_samples, s.seed, s.threads),
        hooks.progress);
    in.seconds["summation"] = seconds_since(t0);
  }
  const std::optional<VerifyTraced> traced =
      all ? std::optional<VerifyTraced>(traced_from_parts(*all, s)) : std::nullopt;
  out.report = run_verify(sample, in, p.measured, s, hooks.progress, traced ? &*traced : nullptr);
  VerifyReport& report = out.report;
  out.cancelled =
      report.cancelled || (p.request.fit && !fit_verify_models(p, sample, in, report, hooks));
  if (out.cancelled) return out;
  report.seconds["total_before_report"] = seconds_since(hooks.started);
  const auto draw = [&](const std::filesystem::path& staging) {
    const auto tp = std::chrono::steady_clock::now();
    hooks.draw(staging);
    report.seconds["plots"] = seconds_since(tp);
  };
  out.cancelled = !write_verify_report(p.request.output, report, draw, hooks.progress);
  return out;
}

}  // namespace

VerifyOutcome run_verify_plan(const VerifyPlan& p, const VerifyHooks& hooks, const JobPart* all) {
  std::optional<JobPart> job;
  if (p.shard) job = verify_job(p, *p.shard);
  if (all) {
    // The inputs must still be those the shards read.
    const JobPart now = verify_job(p, all->shard);
    if (const std::string why = job_difference(*all, now); !why.empty())
      throw Error("", "parts",
                  "the verify job's inputs changed since its shards ran (" + why + ")");
  }
  VerifyInputs in;
  in.fiber_name = p.request.fiber;
  const auto t0 = std::chrono::steady_clock::now();
  VerifyOutcome cancelled;
  cancelled.cancelled = true;
  const std::shared_ptr<const WovenSample> made =
      hooks.sample
          ? hooks.sample(p.weave)
          : std::make_shared<const WovenSample>(make_woven_sample(p.weave, hooks.progress));
  const WovenSample& sample = *made;
  if (sample.cancelled) return cancelled;
  in.sample_name = sample_name(sample.summary);
  if (sample.summary.nonwoven || !sample.summary.notes.empty())
    hooks.note("weft: sample: " + in.sample_name + "\n");
  in.seconds["woven_sample"] = seconds_since(t0);
  // With a colour, the run verifies the spec dyed to it.
  std::optional<VerifyPlan> dyed;
  if (p.colour) {
    const std::optional<FabricColourMatch> m = verify_colour_match(p, sample, hooks);
    if (!m) return cancelled;
    dyed = p;
    dyed->spec = m->match.spec;
    in.colour_match = colour_match_summary(m->match);
    in.colour_match["cached"] = m->cached;
    in.colour_calibrated = p.request.colour_from == "measured";
    in.seconds["colour_match"] = seconds_since(t0) - in.seconds["woven_sample"];
  }
  const VerifyPlan& run = dyed ? *dyed : p;
  if (!fiber_inputs(run, in, hooks)) return cancelled;
  if (job) return run_shard(run, sample, in, *job, hooks);
  return run_report(run, sample, in, hooks, all);
}

}  // namespace weft
