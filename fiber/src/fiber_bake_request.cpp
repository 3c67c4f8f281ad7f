#include "weft/fiber/fiber_bake_request.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"
#include "weft/fiber/bake_cache.h"

namespace weft {

std::string fiber_option_name(const FiberBakeRequest& r, std::string field) {
  if (!r.option_prefix.empty()) std::replace(field.begin(), field.end(), '_', '-');
  return r.option_prefix + field;
}

namespace {

template <class T>
void check_fiber_range(const FiberBakeRequest& r, const std::string& field, T value, T lo, T hi,
                       const std::string& range) {
  if (value < lo || value > hi)
    throw Error("", fiber_option_name(r, field),
                "must be in " + range + ", got " + std::to_string(value));
}

// The bake's options: every option's range and name checked, over the spec's and route's
// defaults (fiber_bake_defaults).
FiberTableBakeOptions fiber_request_options(const FiberBakeRequest& r, const FiberSpec& spec) {
  check_fiber_range(r, "photons", r.photons, uint64_t{1}, kMaxPhotonsPerBand, "[1, 2^40]");
  const int max_r = TabulatedBsdfTable::kMaxResolution;
  check_fiber_range(r, "resolution", r.resolution, 2, max_r, "[2, " + std::to_string(max_r) + "]");
  check_fiber_range(r, "passes", r.passes, uint64_t{1}, kMaxFiberBakePasses, "[1, 2^20]");
  check_fiber_range(r, "threads", r.threads, 0, kMaxFiberBakeThreads,
                    "[0, " + std::to_string(kMaxFiberBakeThreads) + "] (0: all cores)");
  const bool spectral = value_of(kFiberBakeBands, r.bands, "", fiber_option_name(r, "bands"));
  const FiberBakeRoute route =
      value_of(kFiberBakeRoutes, r.route, "", fiber_option_name(r, "route"));
  FiberTableBakeOptions o = fiber_bake_defaults(spec, route);
  o.resolution = r.resolution;
  o.photons_per_band = r.photons;
  o.seed = r.seed;
  o.threads = r.threads;
  o.spectral = spectral;
  o.passes = r.passes;
  if (r.estimator)
    o.estimator = parse_fiber_exit_estimator(*r.estimator, fiber_option_name(r, "estimator"));
  o.mirror_fold = r.mirror_fold;
  if (r.surface_samples) {
    check_fiber_range(r, "surface_samples", *r.surface_samples, 1, kMaxFiberSurfaceSamples,
                      "[1, " + std::to_string(kMaxFiberSurfaceSamples) + "]");
    o.surface_samples = *r.surface_samples;
  }
  if (r.entry) o.entry = parse_fiber_entry_sampling(*r.entry, fiber_option_name(r, "entry"));
  o.surface_lobe =
      value_of(kFiberSurfaceLobes, r.surface_lobe, "", fiber_option_name(r, "surface_lobe"));
  if (o.surface_lobe == FiberSurfaceLobe::kAnalytic &&
      (spec.boundary != FiberBoundary::kSmooth || route != FiberBakeRoute::kDirect))
    throw Error("", fiber_option_name(r, "surface_lobe"),
                "analytic needs the smooth boundary and the direct route (the rough dielectric's "
                "surface part is its microsurface walk, not one Cook-Torrance lobe)");
  return o;
}

// What fixes a fiber bake's bits: a shard's identity (core/job_part.h).
JobPart fiber_bake_job(const std::string& spec_arg, const FiberSpec& spec,
                       const FiberTableBakeOptions& o, Shard shard) {
  JobPart p;
  p.command = "bake fiber";
  p.job = {{"spec_hash", fiber_spec_hash_hex(spec)},
           {"spec_name", spec.name},
           {"resolution", o.resolution},
           {"photons_per_band", o.photons_per_band},
           {"seed", o.seed},
           {"spectral", o.spectral},
           {"route", name_of(kFiberBakeRoutes, o.route)},
           {"max_events_per_photon", o.max_events_per_photon},
           {"passes", o.passes},
           {"program_version", WEFT_VERSION}};
  // Only when not the default, so that parts written before these options still merge.
  if (o.estimator != FiberExitEstimator::kPlain)
    p.job["estimator"] = fiber_exit_estimator_name(o.estimator);
  if (o.mirror_fold) p.job["mirror_fold"] = true;
  if (o.surface_samples != 1) p.job["surface_samples"] = o.surface_samples;
  if (o.entry != FiberEntrySampling::kRandom) p.job["entry"] = fiber_entry_sampling_name(o.entry);
  if (o.surface_lobe != FiberSurfaceLobe::kSampled)
    p.job["surface_lobe"] = name_of(kFiberSurfaceLobes, o.surface_lobe);
  p.units_total = kNumBands;
  p.shard = shard;
  // The spec as given (a merge makes the table's metadata from it; its hash is checked).
  std::error_code ec;
  const bool file = std::filesystem::is_regular_file(spec_arg, ec);
  std::string text;
  if (file) {
    std::ifstream in(spec_arg, std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), {});
  } else {
    text = fiber_preset_json(spec_arg);
  }
  p.extra = {{"spec", text}, {"spec_file", spec_arg}};
  return p;
}

// Doubles before the weighted sums; next-event estimation adds its excess (so plain bakes keep
// the record parts had before it).
size_t fiber_band_header(FiberExitEstimator e) {
  return e == FiberExitEstimator::kPlain ? 13 : 14;
}

std::vector<double> encode_fiber_band(const FiberBandState& s, FiberExitEstimator e) {
  std::vector<double> v;
  v.reserve(fiber_band_header(e) + s.weighted_sum.size());
  push_u64(v, s.passes_done);
  push_u64(v, s.photons);
  push_u64(v, s.events);
  for (double x : {s.mu_s_per_um, s.mu_a_per_um, s.g, s.surface, s.exit, s.absorbed, s.roulette,
                   s.lost, s.excess, s.energy})
    v.push_back(x);
  if (e != FiberExitEstimator::kPlain) v.push_back(s.exit_excess);
  v.insert(v.end(), s.weighted_sum.begin(), s.weighted_sum.end());
  return v;
}

FiberBandState decode_fiber_band(const std::vector<double>& v, FiberExitEstimator e) {
  if (v.size() < fiber_band_header(e)) throw Error("", "units", "a band's record is too short");
  FiberBandState s;
  s.passes_done = as_u64(v[0]), s.photons = as_u64(v[1]), s.events = as_u64(v[2]);
  s.mu_s_per_um = v[3], s.mu_a_per_um = v[4], s.g = v[5], s.surface = v[6], s.exit = v[7];
  s.absorbed = v[8], s.roulette = v[9], s.lost = v[10], s.excess = v[11], s.energy = v[12];
  if (e != FiberExitEstimator::kPlain) s.exit_excess = v[13];
  s.weighted_sum.assign(v.begin() + static_cast<std::ptrdiff_t>(fiber_band_header(e)), v.end());
  return s;
}

// The table of a finished or interrupted whole bake, written to 'output' when there is one.
FiberTableBakeResult write_fiber_table(
    const FiberSpec& spec, const FiberTableBakeOptions& o, const std::vector<FiberBandState>& bands,
    bool cancelled, const std::string& output,
    const std::vector<std::pair<std::string, std::string>>& metadata = {}) {
  FiberTableBakeResult r = finish_fiber_table(spec, o, bands, cancelled);
  r.table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
  for (const auto& [key, value] : metadata) r.table.metadata[key] = value;
  if (!output.empty()) r.table.write_exr(output);
  return r;
}

}  // namespace

FiberBakePlan plan_fiber_bake(const FiberBakeRequest& request,
                              const std::function<void(const std::string&)>& warn) {
  const FiberBakeRequest& r = request;
  FiberBakePlan p;
  p.request = r;
  // The colour's match is a fabric's reading: fabric/fiber_colour.h plans it, then this bake of
  // the matched spec. Here it would be dropped without a word.
  if (!r.colour.empty() || !r.colour_weave.empty())
    throw Error("", fiber_option_name(r, r.colour.empty() ? "colour_weave" : "colour"),
                "is matched by the coloured fiber bake (plan_coloured_fiber_bake), not here");
  const bool writes = !r.output.empty();
  const std::string output_option = fiber_option_name(r, "output");
  if (writes) {
    validate_output_paths(r.limits,
                          {{r.output, output_option}, {checkpoint_path(r.output), "checkpoint"}},
                          {{r.spec, "fiber spec"}});
    // A shard writes a part file for `weft merge`, not a table.
    if (r.shard.empty()) TabulatedBsdfTable::check_output_path(r.output, output_option);
  }
  p.spec = r.spec_read ? *r.spec_read : load_fiber_spec(r.spec);
  p.options = fiber_request_options(r, p.spec);
  if (!r.shard.empty()) p.shard = parse_shard(r.shard, fiber_option_name(r, "shard"));
  p.bands = shard_units(kNumBands, p.shard);
  if (writes) {
    p.job = fiber_bake_job(r.spec, p.spec, p.options, p.shard);
    std::vector<std::string> warnings;
    const auto cp = load_checkpoint(r.output, p.job, r.resume, warnings);
    if (cp) {
      for (const auto& [band, v] : cp->units)
        p.start.push_back(decode_fiber_band(v, p.options.estimator));
      if (p.start.size() != p.bands.last - p.bands.first)
        throw Error(checkpoint_path(r.output).string(), "units",
                    "does not hold every band of the shard");
    }
    if (warn)
      for (const auto& w : warnings) warn(w);
  }
  check_fiber_bake(r.limits, p.options, p.bands.last - p.bands.first,
                   {"", fiber_option_name(r, "photons"), fiber_option_name(r, "resolution")});
  return p;
}

FiberBakeOutcome run_fiber_bake(const FiberBakePlan& p, const FiberBakeHooks& hooks) {
  const FiberBakeRequest& r = p.request;
  const UnitRange range = p.bands;
  FiberBandWork work;
  work.first_band = static_cast<int>(range.first);
  work.last_band = static_cast<int>(range.last);
  work.start = p.start;
  if (r.resume)
    work.on_pass = [&](const std::vector<FiberBandState>& states) {
      JobPart cp = p.job;
      cp.checkpoint = true;
      for (size_t i = 0; i < states.size(); ++i)
        cp.units[range.first + i] = encode_fiber_band(states[i], p.options.estimator);
      write_job_part(checkpoint_path(r.output), cp);
    };
  FiberBakeOutcome out;
  const auto start = std::chrono::steady_clock::now();
  FiberBandsResult traced;
  if (range.last > range.first) {
    try {
      traced = trace_fiber_bands(p.spec, p.options, work, hooks.progress);
    } catch (const Error&) {
      if (!hooks.interrupted()) throw;
      out.interrupted_before_work = true;
      return out;
    }
  }
  out.seconds = seconds_since(start);
  out.cancelled = traced.cancelled;
  if (!p.shard.whole()) {
    if (traced.cancelled) return out;
    JobPart part = p.job;
    for (size_t i = 0; i < traced.bands.size(); ++i)
      part.units[range.first + i] = encode_fiber_band(traced.bands[i], p.options.estimator);
    write_job_part(r.output, part);
    std::filesystem::remove(checkpoint_path(r.output));
    out.part_written = true;
    return out;
  }
  out.table = write_fiber_table(p.spec, p.options, traced.bands, traced.cancelled, r.output,
                                r.table_metadata);
  if (!r.output.empty() && !traced.cancelled) std::filesystem::remove(checkpoint_path(r.output));
  out.summary = fiber_bake_summary(*out.table, p.spec, p.options, r.output, out.seconds);
  return out;
}

namespace {

// An RGB table of a saturated colour is not the fiber: its negative linear-sRGB values were set
// to 0, and a channel can send out more light than hits it (the fabric ray trace refuses that).
std::vector<std::string> rgb_gamut_warnings(const FiberTableBakeResult& r,
                                            const FiberTableBakeOptions& o) {
  std::vector<std::string> out;
  if (o.spectral) return out;
  const std::string keep = "; --bands spectral keeps the colour as it is";
  if (r.rgb_negative_clipped > 0)
    out.push_back(
        "the fiber's colour lies outside the sRGB gamut: the table's linear-sRGB values of f "
        "down to -" +
        ParamReader::fmt(r.rgb_negative_clipped) + " /sr were set to 0" + keep);
  const std::vector<double> albedo = r.table.total_albedo();
  for (size_t c = 0; c < albedo.size(); ++c)
    if (albedo[c] > 1 + kFiberAlbedoAllowance)
      out.push_back("the RGB table's total albedo is " + ParamReader::fmt(albedo[c]) +
                    " in channel " + std::to_string(c) +
                    ", above 1 by more than its tabulation error: a fabric ray trace refuses it" +
                    keep);
  return out;
}

}  // namespace

nlohmann::json fiber_bake_summary(const FiberTableBakeResult& r, const FiberSpec& spec,
                                  const FiberTableBakeOptions& o, const std::string& output,
                                  double seconds) {
  nlohmann::json bands = nlohmann::json::array();
  for (const auto& b : r.bands)
    bands.push_back({{"wavelength_nm", b.wavelength_nm},
                     {"mu_s_per_um", b.mu_s_per_um},
                     {"mu_a_per_um", b.mu_a_per_um},
                     {"g", b.g},
                     {"photons", b.photons},
                     {"surface_reflected", b.surface_fraction},
                     {"albedo", b.exit_fraction},
                     {"absorbed", b.absorbed_fraction},
                     {"lost", b.lost_fraction},
                     {"roulette_net", b.roulette_net},
                     {"surface_sampling_excess", b.surface_sampling_excess},
                     {"expected_exit_excess", b.expected_exit_excess},
                     {"energy_balance", b.energy_balance},
                     {"energy_scale", b.energy_scale},
                     {"table_energy", b.energy_table}});
  nlohmann::json j = {{"output", output},
                      {"spec", spec.name},
                      {"spec_hash", fiber_spec_hash_hex(spec)},
                      {"resolution", o.resolution},
                      {"bands", name_of(kFiberBakeBands, o.spectral)},
                      {"route", name_of(kFiberBakeRoutes, o.route)},
                      {"photons", r.photons},
                      {"scattering_events", r.scattering_events},
                      {"seconds", seconds},
                      {"events_per_s", seconds > 0 ? r.scattering_events / seconds : 0.0},
                      {"photons_per_s", seconds > 0 ? r.photons / seconds : 0.0},
                      {"interrupted", r.cancelled},
                      {"rgb_negative_clipped", r.rgb_negative_clipped},
                      {"per_band", bands}};
  j["warnings"] = rgb_gamut_warnings(r, o);
  return j;
}

FiberBakeOutcome merge_fiber_bake_parts(const JobPart& all, const std::string& output) {
  ParamReader extra(all.extra, "", "extra"), job(all.job, "", "job");
  const FiberSpec spec = parse_fiber_spec(extra.string("spec"), extra.string("spec_file"));
  if (fiber_spec_hash_hex(spec) != job.string("spec_hash"))
    throw Error("", "spec", "the parts' spec does not match their spec hash");
  constexpr uint64_t kAny = std::numeric_limits<uint64_t>::max();
  FiberTableBakeOptions o;
  o.resolution = static_cast<int>(job.count("resolution", 2, TabulatedBsdfTable::kMaxResolution));
  o.photons_per_band = job.count("photons_per_band", 1, kAny);
  o.seed = job.count("seed", 0, kAny);
  o.spectral = job.boolean("spectral", false);
  // choice() names the valid values in a crafted part's refusal, as job files' errors do.
  o.route = value_of(kFiberBakeRoutes, job.choice("route", "", {"direct", "bssrdf"}), "", "route");
  o.max_events_per_photon = job.count("max_events_per_photon", 1, kAny);
  o.passes = job.count("passes", 1, kAny);
  o.estimator = parse_fiber_exit_estimator(job.string("estimator", "plain"), "estimator");
  o.mirror_fold = job.boolean("mirror_fold", false);
  o.surface_samples = static_cast<int>(job.count("surface_samples", 1, 1, kMaxFiberSurfaceSamples));
  o.entry = parse_fiber_entry_sampling(job.string("entry", "random"), "entry");
  o.surface_lobe =
      value_of(kFiberSurfaceLobes, job.choice("surface_lobe", "sampled", {"sampled", "analytic"}),
               "", "surface_lobe");
  const uint64_t passes = std::clamp<uint64_t>(o.passes, 1, o.photons_per_band);
  std::vector<FiberBandState> states;
  for (const auto& [band, v] : all.units) {
    states.push_back(decode_fiber_band(v, o.estimator));
    if (states.back().passes_done != passes)
      throw Error("", "units", "band " + std::to_string(band) + " is unfinished");
  }
  FiberBakeOutcome out;
  out.table = write_fiber_table(spec, o, states, false, output);
  out.summary = fiber_bake_summary(*out.table, spec, o, output, 0);
  return out;
}

}  // namespace weft
