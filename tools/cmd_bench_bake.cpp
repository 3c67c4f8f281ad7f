// weft bench bake: how the error of a baked fiber table falls with photons, and how many photons
// a given relative RMS error needs. Bakes the same spec with K seeds at several photon counts;
// the relative RMS error of a table is sqrt(sum of per-cell variances) / sqrt(sum of squared
// per-cell means), over all cells and bands (an energy-weighted measure: noise in cells that
// hold no light does not dominate it).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/materials/fabric/fiber_table_bake.h"

namespace weft::cli {

void add_bench_bake_command(CLI::App& app, Commands& commands) {
  // "bench" is shared with other benchmark subcommands: reuse it when it exists.
  CLI::App* bench = nullptr;
  try {
    bench = app.get_subcommand("bench");
  } catch (const CLI::OptionNotFound&) {
    bench = app.add_subcommand("bench", "Benchmarks");
    bench->require_subcommand(1);
  }
  struct Options {
    std::string spec = "red-cotton";
    std::string photons = "2000,8000,32000";
    int resolution = 8;
    int seeds = 4;
    double target = 0.01;
    int threads = 0;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd =
      bench->add_subcommand("bake", "Error of a baked fiber table against photons per band");
  cmd->add_option("spec", opt->spec, "fiber spec file or preset (default red-cotton)");
  cmd->add_option("--photons", opt->photons, "photons per band to try, comma list");
  cmd->add_option("--resolution", opt->resolution, "table resolution")->check(CLI::Range(2, 64));
  cmd->add_option("--seeds", opt->seeds, "independent bakes per photon count")
      ->check(CLI::Range(2, 64));
  cmd->add_option("--target", opt->target, "relative RMS error to extrapolate to")
      ->check(CLI::Range(1e-6, 1.0));
  cmd->add_option("--threads", opt->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
  cmd->add_flag("--json", opt->json, "print JSON");
  commands.push_back(
      {cmd, [opt] {
         const FiberSpec spec = load_fiber_spec(opt->spec);
         const auto counts = parse_range(opt->photons, "--photons");
         nlohmann::json rows = nlohmann::json::array();
         double sum_log_n = 0, sum_log_e = 0, sum_ll = 0, sum_nn = 0;
         int points = 0;
         for (double count : counts) {
           if (!(count >= 1)) throw Error("", "--photons", "counts must be >= 1");
           std::vector<double> s, s2;
           const auto start = std::chrono::steady_clock::now();
           for (int k = 0; k < opt->seeds; ++k) {
             FiberTableBakeOptions o;
             o.resolution = opt->resolution;
             o.photons_per_band = static_cast<uint64_t>(count);
             o.seed = 1 + static_cast<uint64_t>(k);
             o.passes = 1;
             o.threads = opt->threads;
             const auto r = bake_fiber_table(spec, o);
             if (s.empty())
               s.assign(r.table.values.size(), 0.0), s2.assign(r.table.values.size(), 0.0);
             for (size_t i = 0; i < s.size(); ++i)
               s[i] += r.table.values[i], s2[i] += double(r.table.values[i]) * r.table.values[i];
           }
           const double seconds =
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
               opt->seeds;
           double var = 0, sq = 0;
           const double k = opt->seeds;
           for (size_t i = 0; i < s.size(); ++i) {
             const double m = s[i] / k;
             var += std::max(0.0, (s2[i] / k - m * m) * k / (k - 1));
             sq += m * m;
           }
           const double rel = sq > 0 ? std::sqrt(var / sq) : 0;
           rows.push_back({{"photons_per_band", count},
                           {"relative_rms_error", rel},
                           {"seconds_per_bake", seconds}});
           if (rel > 0) {
             const double ln = std::log(count), le = std::log(rel);
             sum_log_n += ln, sum_log_e += le, sum_ll += ln * le, sum_nn += ln * ln, ++points;
           }
           if (!opt->json)
             std::fprintf(stderr,
                          "photons/band %10.0f  relative RMS error %.4f  (%.1f s per bake)\n",
                          count, rel, seconds);
         }
         nlohmann::json j = {{"spec", spec.name},
                             {"resolution", opt->resolution},
                             {"seeds", opt->seeds},
                             {"runs", rows}};
         if (points >= 2) {
           // Least-squares fit log(err) = a + b log(N); the Monte Carlo rate is b = -1/2.
           const double b = (points * sum_ll - sum_log_n * sum_log_e) /
                            (points * sum_nn - sum_log_n * sum_log_n);
           const double a = (sum_log_e - b * sum_log_n) / points;
           const double needed = std::exp((std::log(opt->target) - a) / b);
           j["fitted_exponent"] = b;
           j["target_relative_rms_error"] = opt->target;
           j["photons_per_band_for_target"] = needed;
           if (!opt->json)
             std::printf(
                 "error ~ N^%.3f; %.3g photons per band for %.2g %% relative RMS error (R = %d)\n",
                 b, needed, 100 * opt->target, opt->resolution);
         }
         if (opt->json) std::cout << j.dump(2) << "\n";
         return 0;
       }});
}

}  // namespace weft::cli
