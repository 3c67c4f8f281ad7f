#pragma once
// Deterministic parallel photon batches. Photons are split into fixed-size tasks; task k draws
// from Rng(seed, k) and fills its own tally; tallies are merged into the result in task order. So
// the result has the same bits at any thread count. Tasks run in waves; between waves the progress
// callback is called on the calling thread and may cancel: the tasks done so far are kept, and
// the status says how many photons they hold.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/materials/fabric/transport.h"

namespace weft {

// A Monte Carlo mean and its standard error.
struct MeanEstimate {
  double mean = 0;
  double std_error = 0;
};

// Sum and sum of squares of per-photon values.
struct MeanAccumulator {
  double sum = 0, sum2 = 0;

  void add(double x) {
    sum += x;
    sum2 += x * x;
  }
  MeanAccumulator& operator+=(const MeanAccumulator& o) {
    sum += o.sum;
    sum2 += o.sum2;
    return *this;
  }
  // Mean over n samples and the standard error of that mean (unbiased sample variance / n).
  MeanEstimate estimate(uint64_t n) const {
    if (n == 0) return {};
    const double nd = static_cast<double>(n);
    const double mean = sum / nd;
    if (n == 1) return {mean, 0};
    const double var = std::max(0.0, (sum2 - sum * mean) / (nd - 1));
    return {mean, std::sqrt(var / nd)};
  }
};

// Where the power of unit-weight photons went, as fractions with standard errors.
struct PhotonFractions {
  MeanEstimate specular;  // reflected at entry (MCML's rsp)
  MeanEstimate exited;    // left the medium after entering
  MeanEstimate absorbed;
  MeanEstimate roulette;  // roulette losses minus gains (mean zero; nonzero by chance only)
  MeanEstimate lost;      // interaction cap or endless path (see TransportOptions::max_events)
  double energy_imbalance = 0;  // 1 - the sum of the means: zero up to rounding
  uint64_t photons = 0;         // photons traced (fewer than asked when cancelled)
  uint64_t scatterings = 0;     // scattering events in all
  uint64_t reflections = 0;     // internal reflections in all
};

// Per-photon statistics of the energy books (PhotonTally): accumulators for each part of the
// launched power, over the photons added.
struct PhotonStats {
  enum Part { kSpecular, kExited, kAbsorbed, kRoulette, kLost, kParts };
  std::array<MeanAccumulator, kParts> part;
  uint64_t photons = 0, scatterings = 0, reflections = 0;

  void add(const PhotonTally& photon) {
    const double values[kParts] = {photon.specular, photon.exited, photon.absorbed,
                                   photon.roulette_loss - photon.roulette_gain, photon.lost};
    for (int k = 0; k < kParts; ++k) part[k].add(values[k]);
    photons += 1;
    scatterings += photon.scatterings;
    reflections += photon.reflections;
  }
  PhotonStats& operator+=(const PhotonStats& o) {
    for (int k = 0; k < kParts; ++k) part[k] += o.part[k];
    photons += o.photons;
    scatterings += o.scatterings;
    reflections += o.reflections;
    return *this;
  }
  PhotonFractions fractions() const {
    PhotonFractions f;
    MeanEstimate* out[kParts] = {&f.specular, &f.exited, &f.absorbed, &f.roulette, &f.lost};
    double sum = 0;
    for (int k = 0; k < kParts; ++k) {
      *out[k] = part[k].estimate(photons);
      sum += out[k]->mean;
    }
    f.energy_imbalance = photons == 0 ? 0.0 : 1.0 - sum;
    f.photons = photons;
    f.scatterings = scatterings;
    f.reflections = reflections;
    return f;
  }
};

struct PhotonBatchOptions {
  uint64_t photons = 0;
  uint64_t seed = 0;
  int threads = 0;                   // 0: all hardware threads
  uint64_t photons_per_task = 4096;  // fixes the random streams: change it, change the bits
  uint64_t tasks_per_wave = 0;       // 0: 8 per thread; lower it when tallies are large
  ProgressCallback progress;         // may be empty

  void validate() const {
    if (photons_per_task == 0) throw Error("", "photons_per_task", "must be >= 1");
    if (threads < 0) throw Error("", "threads", "must be >= 0");
  }
};

struct PhotonBatchStatus {
  uint64_t photons_done = 0;
  uint64_t tasks_done = 0;
  bool cancelled = false;
};

// The one photon task runner. Runs run(task, first_photon, count, rng, tally) for every task, each
// on a default-constructed TaskTally, and hands the tallies to merge(tally) in task order, so the
// merged result has the same bits at any thread count. Exceptions from run propagate.
template <class TaskTally, class Run, class Merge>
PhotonBatchStatus run_photon_tasks(const PhotonBatchOptions& options, Run&& run, Merge&& merge) {
  options.validate();
  const uint64_t per_task = options.photons_per_task;
  const uint64_t tasks = options.photons / per_task + (options.photons % per_task != 0 ? 1 : 0);
  const int threads = options.threads > 0 ? options.threads : hardware_threads();
  const uint64_t wave =
      options.tasks_per_wave > 0 ? options.tasks_per_wave : 8 * static_cast<uint64_t>(threads);
  PhotonBatchStatus status;
  // A first report before any work starts the front end's clock and allows an early stop.
  if (options.progress && !options.progress(ProgressUpdate{"photons", 0, options.photons})) {
    status.cancelled = tasks > 0;
    return status;
  }
  std::vector<TaskTally> tallies;
  for (uint64_t start = 0; start < tasks; start += wave) {
    const uint64_t n = std::min(wave, tasks - start);
    tallies.assign(n, TaskTally{});
    parallel_for(n, threads, [&](uint64_t i) {
      const uint64_t task = start + i;
      const uint64_t first = task * per_task;
      const uint64_t count = std::min(per_task, options.photons - first);
      Rng rng(options.seed, task);
      run(task, first, count, rng, tallies[i]);
    });
    for (uint64_t i = 0; i < n; ++i) merge(tallies[i]);
    status.tasks_done = start + n;
    status.photons_done = std::min(options.photons, status.tasks_done * per_task);
    if (options.progress &&
        !options.progress(ProgressUpdate{"photons", status.photons_done, options.photons})) {
      status.cancelled = status.tasks_done < tasks;
      break;
    }
  }
  return status;
}

}  // namespace weft
