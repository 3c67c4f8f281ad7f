// weft bench bake: how the error of a baked fiber table falls with photons, and how many photons
// a given relative RMS error needs (the measurement is bench/include/weft/bench/bake_bench.h).
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/bench/bake_bench.h"
#include "weft/core/error.h"

namespace weft::cli {

void add_bench_bake_command(CLI::App& bench, Commands& commands) {
  struct Options {
    std::string spec = "red-cotton";
    std::string photons;  // empty: the benchmark's default counts
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
  cmd->add_flag("--json", opt->json, "print JSON");
  commands.push_back(
      {cmd, [opt] {
         const FiberSpec spec = load_fiber_spec(opt->spec);
         BakeBenchOptions o = opt->bench;
         if (!opt->photons.empty()) {
           o.photons_per_band = parse_range(opt->photons, "--photons");
           for (double count : o.photons_per_band)
             if (!(count >= 1)) throw Error("", "--photons", "counts must be >= 1");
         }
         const BakeBenchResult r = bench_bake(spec, o, [&](const BakeBenchRun& run) {
           if (!opt->json)
             std::fprintf(stderr,
                          "photons/band %10.0f  relative RMS error %.4f  (%.1f s per bake)\n",
                          run.photons_per_band, run.relative_rms_error, run.seconds_per_bake);
         });
         nlohmann::json runs = nlohmann::json::array();
         for (const auto& run : r.runs)
           runs.push_back({{"photons_per_band", run.photons_per_band},
                           {"relative_rms_error", run.relative_rms_error},
                           {"seconds_per_bake", run.seconds_per_bake}});
         nlohmann::json j = {
             {"spec", spec.name}, {"resolution", o.resolution}, {"seeds", o.seeds}, {"runs", runs}};
         if (r.fitted_exponent) {
           j["fitted_exponent"] = *r.fitted_exponent;
           j["target_relative_rms_error"] = o.target;
           j["photons_per_band_for_target"] = *r.photons_per_band_for_target;
           if (!opt->json)
             std::printf(
                 "error ~ N^%.3f; %.3g photons per band for %.2g %% relative RMS "
                 "error (R = %d)\n",
                 *r.fitted_exponent, *r.photons_per_band_for_target, 100 * o.target, o.resolution);
         }
         if (opt->json) std::cout << j.dump(2) << "\n";
         return 0;
       }});
}

}  // namespace weft::cli
