// weft bench flatten: the flattened-fiber experiment (fiber/fiber_layer.h; docs/fabric-bsdf.md,
// "Flattened fibers: an experiment"): beta at normal incidence of a layer of round and of
// flattened fibers of one spec, by view zenith ring, and the peak ratio beta(0) / beta(45), each
// the mean of independent batches (seeds) with its standard error.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/fiber/fiber_layer.h"
#include "weft/fiber/transport_batch.h"

namespace weft::cli {
namespace {

struct FlattenOptions {
  std::string spec = "red-cotton";
  std::string aspects = "1,3";
  std::string csv;
  int batches = 4;
  bool lossless = false;
  FiberLayerSettings layer;
};

// Mean and standard error over the batches of value(batch).
template <class F>
MeanEstimate over_batches(size_t batches, F&& value) {
  MeanAccumulator acc;
  for (size_t b = 0; b < batches; ++b) acc.add(value(b));
  return acc.estimate(batches);
}

nlohmann::json estimate_json(const MeanEstimate& e) {
  return {e.mean, e.std_error};
}

// One aspect: the batches, the CSV rows and the JSON summary.
nlohmann::json run_aspect(const FlattenOptions& o, const FiberSpec& spec, const FiberMedium& medium,
                          double aspect, std::ofstream& csv) {
  std::vector<FiberLayerResult> runs;
  double worst_imbalance = 0, worst_lossless = 0, crossings = 0, photons = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int b = 0; b < o.batches; ++b) {
    FiberLayerSettings s = o.layer;
    s.aspect = aspect;
    s.seed = o.layer.seed + b;
    runs.push_back(simulate_fiber_layer(spec, medium, s));
    for (const auto& band : runs.back().bands) {
      worst_imbalance = std::max(worst_imbalance, std::abs(band.energy_imbalance));
      worst_lossless =
          std::max(worst_lossless, std::abs(band.reflected.mean + band.transmitted.mean - 1));
      crossings += band.fiber_crossings;
      photons += band.photons;
    }
  }
  const double seconds = seconds_since(t0);
  const size_t n = runs.size();
  const int rings = o.layer.rings, k45 = std::min(rings - 1, rings / 2);
  nlohmann::json ratio, reflected, transmitted;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    ratio[names[c]] = estimate_json(over_batches(n, [&](size_t b) {
      return runs[b].reflected_beta[0][c] / runs[b].reflected_beta[k45][c];
    }));
    reflected[names[c]] =
        estimate_json(over_batches(n, [&](size_t b) { return runs[b].reflected[c]; }));
    transmitted[names[c]] =
        estimate_json(over_batches(n, [&](size_t b) { return runs[b].transmitted[c]; }));
  }
  // The same ratio in plain band averages (no sRGB reduction, so no cancellation between bands):
  // red 600-700 nm, green 500-570 nm, blue 420-480 nm.
  nlohmann::json band_ratio;
  const double groups[3][2] = {{600, 700}, {500, 570}, {420, 480}};
  for (int c = 0; c < 3; ++c)
    band_ratio[names[c]] = estimate_json(over_batches(n, [&](size_t b) {
      double top = 0, side = 0;
      for (size_t k = 0; k < medium.bands.size(); ++k) {
        const double nm = medium.bands[k].wavelength_nm;
        if (nm < groups[c][0] - 1e-9 || nm > groups[c][1] + 1e-9) continue;
        top += runs[b].bands[k].reflected_beta[0].mean;
        side += runs[b].bands[k].reflected_beta[k45].mean;
      }
      return top / side;
    }));
  for (int k = 0; k < rings && csv; ++k)
    for (int side = 0; side < 2; ++side) {
      csv << aspect << "," << o.layer.tilt_spread_deg << "," << o.layer.crimp_deg << ","
          << o.layer.yarn_tilt_deg << "," << (side ? "transmitted" : "reflected") << ","
          << 90.0 * k / rings << "," << 90.0 * (k + 1) / rings;
      for (int part = 0; part < 2; ++part)
        for (int c = 0; c < 3; ++c) {
          const MeanEstimate e = over_batches(n, [&](size_t b) {
            return (side ? runs[b].transmitted_beta : runs[b].reflected_beta)[k][c];
          });
          csv << "," << (part ? e.std_error : e.mean);
        }
      csv << "\n";
    }
  nlohmann::json j = {{"aspect", aspect},
                      {"tilt_spread_deg", o.layer.tilt_spread_deg},
                      {"crimp_deg", o.layer.crimp_deg},
                      {"yarn_tilt_deg", o.layer.yarn_tilt_deg},
                      {"peak_ratio_ring0_over_ring45", ratio},
                      {"peak_ratio_band_averages", band_ratio},
                      {"reflected", reflected},
                      {"transmitted", transmitted},
                      {"worst_band_energy_imbalance", worst_imbalance},
                      {"crossings_per_photon", crossings / photons},
                      {"photons", photons},
                      {"seconds", seconds}};
  if (o.lossless) j["worst_band_reflected_plus_transmitted_minus_1"] = worst_lossless;
  return j;
}

}  // namespace

void add_bench_flatten_command(CLI::App& bench, Commands& commands) {
  auto o = std::make_shared<FlattenOptions>();
  o->layer.rings = 9;
  auto* cmd = bench.add_subcommand(
      "flatten", "Round vs flattened fibers: a fiber layer's beta at normal incidence");
  cmd->add_option("spec", o->spec, "fiber spec file or preset (default red-cotton)");
  cmd->add_option("--aspects", o->aspects, "width:thickness ratios to try, comma list")
      ->capture_default_str();
  cmd->add_option("--photons", o->layer.photons_per_band, "photons per band and batch")
      ->capture_default_str();
  cmd->add_option("--batches", o->batches, "independent batches (seeds)")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  cmd->add_option("--rows", o->layer.rows, "rows of fibers")->capture_default_str();
  cmd->add_option("--fibers-per-row", o->layer.fibers_per_row, "fibers per row and period")
      ->capture_default_str();
  cmd->add_option("--pitch-um", o->layer.pitch_um, "centre spacing within a row")
      ->capture_default_str();
  cmd->add_option("--tilt-spread-deg", o->layer.tilt_spread_deg, "long axis tilt, +- degrees")
      ->capture_default_str();
  cmd->add_option("--crimp-deg", o->layer.crimp_deg, "fiber axes out of the cloth's plane, max")
      ->capture_default_str();
  cmd->add_option("--yarn-tilt-deg", o->layer.yarn_tilt_deg, "patch about the fiber axes, max")
      ->capture_default_str();
  cmd->add_option("--rings", o->layer.rings, "view zenith rings over 0-90 degrees")
      ->capture_default_str();
  cmd->add_option("--seed", o->layer.seed, "seed of the first batch")->capture_default_str();
  cmd->add_option("--threads", o->layer.threads, "threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--lossless", o->lossless, "the spec's fiber without absorption (energy check)");
  cmd->add_option("--csv", o->csv, "write the rings: beta per channel and its standard error");
  commands.push_back(
      {cmd, [o](const RunLimits&) {
         const FiberSpec spec = load_fiber_spec(o->spec);
         FiberMedium medium = build_fiber_medium(spec);
         if (o->lossless)
           for (MediumBand& b : medium.bands) {
             b.mu_a_per_um = b.mu_a_host_per_um = b.mu_a_particles_per_um = 0;
             b.albedo = b.mu_s_per_um > 0 ? 1.0 : 0.0;
           }
         std::ofstream csv;
         if (!o->csv.empty()) {
           csv.open(o->csv);
           if (!csv) throw Error(o->csv, "--csv", "cannot write");
           csv << "aspect,tilt_spread_deg,crimp_deg,yarn_tilt_deg,side,theta_lo_deg,"
                  "theta_hi_deg,beta_R,beta_G,beta_B,err_R,err_G,err_B\n";
         }
         nlohmann::json runs = nlohmann::json::array();
         for (double aspect : parse_range(o->aspects, "--aspects")) {
           runs.push_back(run_aspect(*o, spec, medium, aspect, csv));
           std::fprintf(stderr, "aspect %g: %.1f s\n", aspect,
                        runs.back()["seconds"].get<double>());
         }
         std::cout << nlohmann::json{{"spec", spec.name}, {"lossless", o->lossless}, {"runs", runs}}
                          .dump(2)
                   << "\n";
         return 0;
       }});
}

}  // namespace weft::cli
