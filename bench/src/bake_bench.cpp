#include "weft/bench/bake_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

#include "weft/core/clock.h"
#include "weft/core/error.h"

namespace weft {

void CellMoments::add(std::span<const float> table) {
  if (count_ == 0) sum_.assign(table.size(), 0.0), sum_sq_.assign(table.size(), 0.0);
  if (table.size() != sum_.size()) throw Error("tables of different sizes");
  for (size_t i = 0; i < sum_.size(); ++i)
    sum_[i] += table[i], sum_sq_[i] += double(table[i]) * table[i];
  ++count_;
}

double CellMoments::relative_rms_error() const {
  if (count_ < 2) throw Error("the relative RMS error needs two tables or more");
  double var = 0, sq = 0;
  const double k = count_;
  for (size_t i = 0; i < sum_.size(); ++i) {
    const double m = sum_[i] / k;
    var += std::max(0.0, (sum_sq_[i] / k - m * m) * k / (k - 1));  // unbiased per-cell variance
    sq += m * m;
  }
  return sq > 0 ? std::sqrt(var / sq) : 0;
}

double PowerLawFit::x_at(double y) const {
  return std::exp((std::log(y) - a) / b);
}

std::optional<PowerLawFit> fit_power_law(std::span<const double> x, std::span<const double> y) {
  double sum_lx = 0, sum_ly = 0, sum_lxly = 0, sum_lxlx = 0;
  int n = 0;
  for (size_t i = 0; i < x.size() && i < y.size(); ++i) {
    if (!(y[i] > 0)) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sum_lx += lx, sum_ly += ly, sum_lxly += lx * ly, sum_lxlx += lx * lx, ++n;
  }
  if (n < 2) return std::nullopt;
  PowerLawFit f;
  f.b = (n * sum_lxly - sum_lx * sum_ly) / (n * sum_lxlx - sum_lx * sum_lx);
  f.a = (sum_ly - f.b * sum_lx) / n;
  return f;
}

BakeBenchResult bench_bake(const FiberSpec& spec, const BakeBenchOptions& options,
                           const std::function<void(const BakeBenchRun&)>& on_run) {
  if (options.seeds < 2) throw Error("", "seeds", "needs at least 2 independent bakes");
  for (double count : options.photons_per_band)
    if (!(count >= 1)) throw Error("", "photons_per_band", "counts must be >= 1");
  BakeBenchResult result;
  std::vector<double> photons, errors;
  for (double count : options.photons_per_band) {
    CellMoments moments;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    for (int k = 0; k < options.seeds; ++k) {
      FiberTableBakeOptions o;
      o.resolution = options.resolution;
      o.photons_per_band = static_cast<uint64_t>(count);
      o.seed = 1 + static_cast<uint64_t>(k);
      o.passes = 1;
      o.threads = options.threads;
      o.estimator = options.estimator;
      o.mirror_fold = options.mirror_fold;
      o.surface_samples = options.surface_samples;
      o.entry = options.entry;
      moments.add(bake_fiber_table(spec, o).table.values);
    }
    BakeBenchRun run;
    run.photons_per_band = count;
    run.seconds_per_bake = seconds_since(start) / options.seeds;
    run.cpu_seconds_per_bake =
        static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / options.seeds;
    run.relative_rms_error = moments.relative_rms_error();
    result.runs.push_back(run);
    photons.push_back(count);
    errors.push_back(run.relative_rms_error);
    if (on_run) on_run(run);
  }
  if (const auto fit = fit_power_law(photons, errors)) {
    result.fitted_exponent = fit->b;
    result.photons_per_band_for_target = fit->x_at(options.target);
  }
  const auto [lo, hi] = std::minmax_element(result.runs.begin(), result.runs.end(),
                                            [](const BakeBenchRun& a, const BakeBenchRun& b) {
                                              return a.photons_per_band < b.photons_per_band;
                                            });
  if (lo != result.runs.end() && hi->photons_per_band > lo->photons_per_band) {
    const double slope = (hi->cpu_seconds_per_bake - lo->cpu_seconds_per_bake) /
                         (hi->photons_per_band - lo->photons_per_band);
    result.cpu_seconds_per_photon_per_band = slope;
    if (result.photons_per_band_for_target)
      result.cpu_seconds_for_target =
          lo->cpu_seconds_per_bake +
          slope * (*result.photons_per_band_for_target - lo->photons_per_band);
  }
  return result;
}

}  // namespace weft
