// weft bench bake: how the error of a baked fiber table falls with photons, and how many photons
// a given relative RMS error needs (the measurement is bench/include/weft/bench/bake_bench.h).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "weft/bench/bake_bench.h"
#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft::cli {

namespace {

// "plain,nee+mirror+s4" -> the variants' names and bench options: an estimator, then optionally
// "mirror" (mirror folding), "strat" (stratified entries) and "s<K>" (K surface samples), joined
// by '+' (weft::Error naming --estimators).
std::vector<std::pair<std::string, BakeBenchOptions>> parse_bake_variants(
    const std::string& list, const BakeBenchOptions& base) {
  std::vector<std::pair<std::string, BakeBenchOptions>> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) {
    // A variant names all its options: "plain" is the bare bake whatever the bake's defaults.
    BakeBenchOptions v = base;
    v.mirror_fold = false;
    v.surface_samples = 1;
    v.entry = FiberEntrySampling::kRandom;
    std::stringstream parts(item);
    std::string part;
    std::getline(parts, part, '+');
    v.estimator = parse_fiber_exit_estimator(part, "--estimators");
    while (std::getline(parts, part, '+')) {
      if (part == "mirror")
        v.mirror_fold = true;
      else if (part == "strat")
        v.entry = FiberEntrySampling::kStratified;
      else if (const auto k =
                   part.size() > 1 && part[0] == 's' ? finite_number(part.substr(1)) : std::nullopt;
               k && *k >= 1 && *k <= 1024 && *k == std::floor(*k))
        v.surface_samples = static_cast<int>(*k);
      else
        throw Error("", "--estimators",
                    "unknown modifier '" + part + "' (mirror, strat or s<K>, K in 1..1024)");
    }
    out.emplace_back(item, v);
  }
  if (out.empty()) throw Error("", "--estimators", "name at least one variant");
  return out;
}

// One variant's runs and fit, as JSON (progress on stderr unless 'quiet').
nlohmann::json run_bake_variant(const FiberSpec& spec, const std::string& name,
                                const BakeBenchOptions& o, bool quiet) {
  const BakeBenchResult r = bench_bake(spec, o, [&](const BakeBenchRun& run) {
    if (!quiet)
      std::fprintf(stderr,
                   "%-12s photons/band %10.0f  relative RMS error %.4f  (%.1f s, %.1f CPU s per "
                   "bake)\n",
                   name.c_str(), run.photons_per_band, run.relative_rms_error, run.seconds_per_bake,
                   run.cpu_seconds_per_bake);
  });
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& run : r.runs)
    runs.push_back({{"photons_per_band", run.photons_per_band},
                    {"relative_rms_error", run.relative_rms_error},
                    {"seconds_per_bake", run.seconds_per_bake},
                    {"cpu_seconds_per_bake", run.cpu_seconds_per_bake}});
  nlohmann::json j = {{"estimator", name}, {"runs", runs}};
  if (r.fitted_exponent) {
    j["fitted_exponent"] = *r.fitted_exponent;
    j["target_relative_rms_error"] = o.target;
    j["photons_per_band_for_target"] = *r.photons_per_band_for_target;
  }
  if (r.cpu_seconds_per_photon_per_band)
    j["cpu_seconds_per_photon_per_band"] = *r.cpu_seconds_per_photon_per_band;
  if (r.cpu_seconds_for_target) j["cpu_seconds_for_target"] = *r.cpu_seconds_for_target;
  return j;
}

// The variants side by side, ratios against the first.
void print_bake_comparison(const nlohmann::json& variants, double target) {
  const nlohmann::json& first = variants.front();
  for (const auto& v : variants) {
    if (!v.contains("photons_per_band_for_target")) continue;
    const double n = v["photons_per_band_for_target"], cpu = v.value("cpu_seconds_for_target", 0.0);
    std::printf("%-12s error ~ N^%.3f; %.3g photons per band for %.2g %% (%.3g CPU s)",
                v["estimator"].get<std::string>().c_str(), v["fitted_exponent"].get<double>(), n,
                100 * target, cpu);
    if (&v != &first && first.contains("photons_per_band_for_target")) {
      const double n0 = first["photons_per_band_for_target"];
      const double cpu0 = first.value("cpu_seconds_for_target", 0.0);
      std::printf("  photons / %.3g, CPU / %.3g", n0 / n, cpu > 0 ? cpu0 / cpu : 0.0);
    }
    std::printf("\n");
  }
}

}  // namespace

void add_bench_bake_command(CLI::App& bench, Commands& commands) {
  struct Options {
    std::string spec = "red-cotton";
    std::string photons;  // empty: the benchmark's default counts
    std::string estimators = "plain";
    BakeBenchOptions bench;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  std::string default_counts;
  for (double n : opt->bench.photons_per_band)
    default_counts += (default_counts.empty() ? "" : ",") + std::to_string(uint64_t(n));
  auto* cmd = bench.add_subcommand("bake", "Error of a baked fiber table against photons per band");
  cmd->add_option("spec", opt->spec, "fiber spec file or preset (default red-cotton)");
  cmd->add_option("--photons", opt->photons,
                  "photons per band to try, comma list (default " + default_counts + ")");
  cmd->add_option("--resolution", opt->bench.resolution, "table resolution")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  cmd->add_option("--seeds", opt->bench.seeds, "independent bakes per photon count")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  cmd->add_option("--target", opt->bench.target, "relative RMS error to extrapolate to")
      ->check(finite_range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_option("--threads", opt->bench.threads, "threads (0 = all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_option("--estimators", opt->estimators,
                  "bake variants to compare, comma list of plain or nee, each optionally with "
                  "+mirror (mirror folding), +strat (stratified entries) and +s<K> (K surface "
                  "samples per photon); ratios are against the first")
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "print JSON");
  commands.push_back(
      {cmd, [opt](const RunLimits&) {
         const FiberSpec spec = load_fiber_spec(opt->spec);
         BakeBenchOptions o = opt->bench;
         if (!opt->photons.empty()) {
           o.photons_per_band = parse_range(opt->photons, "--photons");
           for (double count : o.photons_per_band)
             if (!(count >= 1)) throw Error("", "--photons", "counts must be >= 1");
         }
         const auto variants = parse_bake_variants(opt->estimators, o);
         nlohmann::json out = nlohmann::json::array();
         for (const auto& [name, v] : variants)
           out.push_back(run_bake_variant(spec, name, v, opt->json));
         if (!opt->json) print_bake_comparison(out, o.target);
         nlohmann::json j = {{"spec", spec.name}, {"resolution", o.resolution}, {"seeds", o.seeds}};
         // One variant keeps the report's former shape; several are listed.
         if (out.size() == 1)
           j.update(out[0]);
         else
           j["variants"] = out;
         if (opt->json) std::cout << j.dump(2) << "\n";
         return 0;
       }});
}

}  // namespace weft::cli
