// weft bake fiber: a fiber spec (file or preset) -> fiber BSDF table (.exr) + JSON summary.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/job_part.h"
#include "weft/core/params.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft::cli {

namespace {

// The summary of a bake (or of a merge of its shards) on stdout.
int report_fiber_bake(const FiberTableBakeResult& r, const FiberSpec& spec,
                      const FiberTableBakeOptions& o, const std::string& output, double seconds,
                      bool json) {
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
                      {"bands", o.spectral ? "spectral" : "rgb"},
                      {"route", o.route == FiberBakeRoute::kDirect ? "direct" : "bssrdf"},
                      {"photons", r.photons},
                      {"scattering_events", r.scattering_events},
                      {"seconds", seconds},
                      {"events_per_s", seconds > 0 ? r.scattering_events / seconds : 0.0},
                      {"photons_per_s", seconds > 0 ? r.photons / seconds : 0.0},
                      {"interrupted", r.cancelled},
                      {"rgb_negative_clipped", r.rgb_negative_clipped},
                      {"per_band", bands}};
  if (json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("baked %s (%s) -> %s\n", spec.name.c_str(), fiber_spec_hash_hex(spec).c_str(),
                output.c_str());
    std::printf("%llu photons, %llu scattering events in %.1f s (%.3g events/s)%s\n",
                static_cast<unsigned long long>(r.photons),
                static_cast<unsigned long long>(r.scattering_events), seconds,
                seconds > 0 ? r.scattering_events / seconds : 0.0,
                r.cancelled ? "  [interrupted: table holds the finished passes]" : "");
    std::printf("  nm    mu_s/um   mu_a/um    g     surface  albedo  absorbed  balance\n");
    for (const auto& b : r.bands)
      std::printf("  %3.0f  %8.4f  %8.5f  %5.3f  %6.4f  %6.4f  %6.4f  %6.4f\n", b.wavelength_nm,
                  b.mu_s_per_um, b.mu_a_per_um, b.g, b.surface_fraction, b.exit_fraction,
                  b.absorbed_fraction, b.energy_balance);
  }
  if (r.cancelled) std::fprintf(stderr, "weft: interrupted; wrote the finished passes\n");
  return r.cancelled ? 130 : 0;
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
           {"route", o.route == FiberBakeRoute::kDirect ? "direct" : "bssrdf"},
           {"max_events_per_photon", o.max_events_per_photon},
           {"passes", o.passes},
           {"program_version", WEFT_VERSION}};
  // Only when not the default, so that parts written before these options still merge.
  if (o.estimator != FiberExitEstimator::kPlain)
    p.job["estimator"] = fiber_exit_estimator_name(o.estimator);
  if (o.mirror_fold) p.job["mirror_fold"] = true;
  if (o.surface_samples != 1) p.job["surface_samples"] = o.surface_samples;
  if (o.entry != FiberEntrySampling::kRandom) p.job["entry"] = fiber_entry_sampling_name(o.entry);
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
size_t band_header(FiberExitEstimator e) {
  return e == FiberExitEstimator::kPlain ? 13 : 14;
}

std::vector<double> encode_fiber_band(const FiberBandState& s, FiberExitEstimator e) {
  std::vector<double> v;
  v.reserve(band_header(e) + s.weighted_sum.size());
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
  if (v.size() < band_header(e)) throw Error("", "units", "a band's record is too short");
  FiberBandState s;
  s.passes_done = as_u64(v[0]), s.photons = as_u64(v[1]), s.events = as_u64(v[2]);
  s.mu_s_per_um = v[3], s.mu_a_per_um = v[4], s.g = v[5], s.surface = v[6], s.exit = v[7];
  s.absorbed = v[8], s.roulette = v[9], s.lost = v[10], s.excess = v[11], s.energy = v[12];
  if (e != FiberExitEstimator::kPlain) s.exit_excess = v[13];
  s.weighted_sum.assign(v.begin() + static_cast<std::ptrdiff_t>(band_header(e)), v.end());
  return s;
}

}  // namespace

int merge_fiber_bake(const JobPart& all, const std::string& output, bool json) {
  // The parts are a user's files: every setting is read through the checks a job file gets, so
  // a corrupt or crafted part is refused naming the setting, never cast out of range.
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
  o.route = job.choice("route", "", {"direct", "bssrdf"}) == "direct" ? FiberBakeRoute::kDirect
                                                                      : FiberBakeRoute::kBssrdf;
  o.max_events_per_photon = job.count("max_events_per_photon", 1, kAny);
  o.passes = job.count("passes", 1, kAny);
  o.estimator = parse_fiber_exit_estimator(job.string("estimator", "plain"), "estimator");
  o.mirror_fold = job.boolean("mirror_fold", false);
  o.surface_samples = static_cast<int>(job.count("surface_samples", 1, 1, 1024));
  o.entry = parse_fiber_entry_sampling(job.string("entry", "random"), "entry");
  const uint64_t passes = std::clamp<uint64_t>(o.passes, 1, o.photons_per_band);
  std::vector<FiberBandState> states;
  for (const auto& [band, v] : all.units) {
    states.push_back(decode_fiber_band(v, o.estimator));
    if (states.back().passes_done != passes)
      throw Error("", "units", "band " + std::to_string(band) + " is unfinished");
  }
  FiberTableBakeResult r = finish_fiber_table(spec, o, states, false);
  r.table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
  r.table.write_exr(output);
  return report_fiber_bake(r, spec, o, output, 0, json);
}

void add_bake_command(CLI::App& app, Commands& commands) {
  auto* bake = app.add_subcommand("bake", "Bake BSDF tables from physical specs");
  bake->require_subcommand(1);
  add_bake_fabric_command(*bake, commands);

  struct Options {
    std::string spec;
    std::string output;
    uint64_t photons = FiberTableBakeOptions{}.photons_per_band;
    int resolution = FiberTableBakeOptions{}.resolution;
    std::string bands = "spectral";
    std::string route = "direct";
    // Empty or 0: the spec's and route's default (fiber_bake_defaults).
    std::string estimator;
    bool mirror_fold = FiberTableBakeOptions{}.mirror_fold;
    int surface_samples = 0;
    std::string entry;
    uint64_t seed = FiberTableBakeOptions{}.seed;
    uint64_t passes = FiberTableBakeOptions{}.passes;
    int threads = 0;
    std::string shard;
    bool resume = false;
    bool json = false;
    bool quiet = false;
  };
  auto opt = std::make_shared<Options>();
  auto* fiber = bake->add_subcommand(
      "fiber", "Fiber BSDF table: Mie medium -> photon transport in the fiber -> table");
  fiber
      ->add_option(
          "spec", opt->spec,
          "fiber spec JSON file, or a preset name (" +
              [] {
                std::string s;
                for (const auto& n : fiber_preset_names()) s += (s.empty() ? "" : ", ") + n;
                return s;
              }() +
              ")")
      ->required();
  fiber->add_option("-o,--output", opt->output, "output table (.exr)")->required();
  fiber->add_option("--photons", opt->photons, "photons per band")
      ->check(CLI::Range(uint64_t{1}, kMaxPhotonsPerBand));
  fiber
      ->add_option("--resolution", opt->resolution,
                   "bins per side of the equal-area square per direction")
      ->check(CLI::Range(2, TabulatedBsdfTable::kMaxResolution));
  fiber
      ->add_option("--bands", opt->bands,
                   "spectral (33 bands, 390-710 nm) or rgb (linear sRGB, D65)")
      ->check(CLI::IsMember({"spectral", "rgb"}));
  fiber->add_option("--route", opt->route, "direct (parallel beam) or bssrdf (the paper's route)")
      ->check(CLI::IsMember({"direct", "bssrdf"}));
  fiber
      ->add_option("--estimator", opt->estimator,
                   "how exits are tallied: plain (one by one) or nee (next-event estimation at "
                   "every scattering, the table scaled to the walks' own exits; smooth boundary, "
                   "direct route); default nee where it applies")
      ->check(CLI::IsMember({"plain", "nee"}));
  fiber->add_flag("--mirror-fold,!--no-mirror-fold", opt->mirror_fold,
                  "average every cell with its images under the fiber's mirror symmetries "
                  "(default on; --no-mirror-fold turns it off)");
  fiber
      ->add_option("--surface-samples", opt->surface_samples,
                   "surface-lobe directions drawn per photon (smooth boundary; default " +
                       std::to_string(FiberTableBakeOptions{}.surface_samples) + ")")
      ->check(CLI::Range(1, 1024));
  fiber
      ->add_option("--entry", opt->entry,
                   "how photons' entries are drawn: random or stratified (randomised Sobol' "
                   "points per task; direct route); default stratified on the direct route")
      ->check(CLI::IsMember({"random", "stratified"}));
  fiber->add_option("--seed", opt->seed, "random seed");
  fiber
      ->add_option("--passes", opt->passes,
                   "passes over all bands (an interrupted bake keeps finished passes)")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 20));
  fiber->add_option("--threads", opt->threads, "threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  fiber->add_option("--shard", opt->shard,
                    "K/N: trace only shard K of N (bands) into a part file for `weft merge`");
  fiber->add_flag("--resume", opt->resume,
                  "checkpoint every finished pass beside the output and continue from a "
                  "checkpoint an earlier run of this bake left there");
  fiber->add_flag("--json", opt->json, "print the summary as JSON");
  fiber->add_flag("--quiet", opt->quiet, "no progress bar");

  commands.push_back(
      {fiber, [opt](const RunLimits& program) {
         const RunLimits limits = quieted(program, opt->quiet);
         validate_output_paths(
             limits, {{opt->output, "--output"}, {checkpoint_path(opt->output), "checkpoint"}},
             {{opt->spec, "fiber spec"}});
         // A shard writes a part file for `weft merge`, not a table.
         if (opt->shard.empty()) TabulatedBsdfTable::check_output_path(opt->output, "--output");
         const FiberSpec spec = load_fiber_spec(opt->spec);
         const FiberBakeRoute route =
             opt->route == "direct" ? FiberBakeRoute::kDirect : FiberBakeRoute::kBssrdf;
         FiberTableBakeOptions o = fiber_bake_defaults(spec, route);
         o.resolution = opt->resolution;
         o.photons_per_band = opt->photons;
         o.seed = opt->seed;
         o.threads = opt->threads;
         o.spectral = opt->bands == "spectral";
         o.passes = opt->passes;
         if (!opt->estimator.empty())
           o.estimator = parse_fiber_exit_estimator(opt->estimator, "--estimator");
         o.mirror_fold = opt->mirror_fold;
         if (opt->surface_samples > 0) o.surface_samples = opt->surface_samples;
         if (!opt->entry.empty()) o.entry = parse_fiber_entry_sampling(opt->entry, "--entry");
         const Shard shard = opt->shard.empty() ? Shard{} : parse_shard(opt->shard, "--shard");
         const JobPart job = fiber_bake_job(opt->spec, spec, o, shard);
         const UnitRange range = shard_units(kNumBands, shard);
         FiberBandWork work;
         work.first_band = static_cast<int>(range.first);
         work.last_band = static_cast<int>(range.last);
         std::vector<std::string> warnings;
         if (const auto cp = load_checkpoint(opt->output, job, opt->resume, warnings)) {
           for (const auto& [band, v] : cp->units)
             work.start.push_back(decode_fiber_band(v, o.estimator));
           if (work.start.size() != range.last - range.first)
             throw Error(checkpoint_path(opt->output).string(), "units",
                         "does not hold every band of the shard");
         }
         for (const auto& w : warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
         if (opt->resume)
           work.on_pass = [&](const std::vector<FiberBandState>& states) {
             JobPart cp = job;
             cp.checkpoint = true;
             for (size_t i = 0; i < states.size(); ++i)
               cp.units[range.first + i] = encode_fiber_band(states[i], o.estimator);
             write_job_part(checkpoint_path(opt->output), cp);
           };
         check_fiber_bake(limits, o, range.last - range.first, {"", "--photons", "--resolution"});
         const auto start = std::chrono::steady_clock::now();
         FiberBandsResult traced;
         if (range.last > range.first) {
           try {
             traced = trace_fiber_bands(spec, o, work, progress_bar(limits, opt->quiet));
           } catch (const Error&) {
             if (!interrupted()) throw;
             std::fprintf(stderr, "\nweft: interrupted before any photon; nothing was written\n");
             return 130;
           }
         }
         const double seconds = seconds_since(start);
         if (!shard.whole()) {
           if (traced.cancelled) {
             std::fprintf(stderr, "\nweft: interrupted; no part written%s\n",
                          opt->resume ? " (--resume continues from the last finished pass)" : "");
             return 130;
           }
           JobPart part = job;
           for (size_t i = 0; i < traced.bands.size(); ++i)
             part.units[range.first + i] = encode_fiber_band(traced.bands[i], o.estimator);
           write_job_part(opt->output, part);
           std::filesystem::remove(checkpoint_path(opt->output));
           std::printf("bands %llu..%llu of %s (shard %u/%u) -> %s in %.1f s\n",
                       static_cast<unsigned long long>(range.first),
                       static_cast<unsigned long long>(range.last), spec.name.c_str(), shard.index,
                       shard.count, opt->output.c_str(), seconds);
           return 0;
         }
         FiberTableBakeResult r = finish_fiber_table(spec, o, traced.bands, traced.cancelled);
         r.table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
         r.table.write_exr(opt->output);
         if (!r.cancelled) std::filesystem::remove(checkpoint_path(opt->output));
         return report_fiber_bake(r, spec, o, opt->output, seconds, opt->json);
       }});
}

}  // namespace weft::cli
