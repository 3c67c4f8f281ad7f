#pragma once
// How the error of a baked fiber table falls with photons (`weft bench bake`): the same spec baked
// with K independent seeds at several photon counts. The relative RMS error of a table is
// sqrt(sum of per-cell variances) / sqrt(sum of squared per-cell means), over all cells and bands
// (an energy-weighted measure: noise in cells that hold no light does not dominate it). A
// least-squares fit of log(error) against log(photons) extrapolates to the photons a target error
// needs (Monte Carlo's rate is an exponent of -1/2).
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft {

struct BakeBenchOptions {
  std::vector<double> photons_per_band = {2000, 8000, 32000};
  int resolution = FiberTableBakeOptions{}.resolution;
  int seeds = 4;         // independent bakes per photon count (at least 2)
  double target = 0.01;  // relative RMS error to extrapolate to
  int threads = FiberTableBakeOptions{}.threads;
  // The bake's variance reduction (fiber_table_bake.h).
  FiberExitEstimator estimator = FiberTableBakeOptions{}.estimator;
  bool mirror_fold = FiberTableBakeOptions{}.mirror_fold;
  int surface_samples = FiberTableBakeOptions{}.surface_samples;
  FiberEntrySampling entry = FiberTableBakeOptions{}.entry;
};

struct BakeBenchRun {
  double photons_per_band = 0;
  double relative_rms_error = 0;
  double seconds_per_bake = 0;
  double cpu_seconds_per_bake = 0;  // this process's CPU time (all threads)
};

struct BakeBenchResult {
  std::vector<BakeBenchRun> runs;
  // With two or more runs of non-zero error: error ~ N^fitted_exponent, and the photons per band
  // at which the fit reaches options.target.
  std::optional<double> fitted_exponent, photons_per_band_for_target;
  // With two or more photon counts: the CPU time of one more photon per band, seconds (the slope
  // of CPU time per bake between the smallest and the largest count: the Mie medium and the table's
  // fixed costs cancel), and so the CPU seconds of a bake at the target.
  std::optional<double> cpu_seconds_per_photon_per_band, cpu_seconds_for_target;
};

// 'on_run' sees each run as it finishes (for progress).
BakeBenchResult bench_bake(const FiberSpec& spec, const BakeBenchOptions& options,
                           const std::function<void(const BakeBenchRun&)>& on_run = {});

// Per-cell moments over independent estimates of the same table.
class CellMoments {
 public:
  void add(std::span<const float> table);
  // The relative RMS error of one table (0 when every mean is 0); needs two tables or more.
  double relative_rms_error() const;

 private:
  std::vector<double> sum_, sum_sq_;
  int count_ = 0;
};

// Least-squares fit of log y = a + b log x over the points with y > 0.
struct PowerLawFit {
  double a = 0, b = 0;
  double x_at(double y) const;  // where the fit reaches y
};
std::optional<PowerLawFit> fit_power_law(std::span<const double> x, std::span<const double> y);

}  // namespace weft
