#pragma once
// Per-photon statistics of the energy books. Photons run as tasks on the project's one
// deterministic batch runner (core/task_batch.h, TaskBatch: items are photons).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/core/task_batch.h"
#include "weft/fiber/transport.h"

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
  // Expected exits recorded minus the walk's exits they stand for (TransportOptions::
  // expected_exits; mean zero, else exactly zero).
  MeanEstimate expected_exit_excess;
  double energy_imbalance = 0;  // 1 - the sum of the means (less the excess): zero to rounding
  uint64_t photons = 0;         // photons traced (fewer than asked when cancelled)
  uint64_t scatterings = 0;     // scattering events in all
  uint64_t reflections = 0;     // internal reflections in all
};

// Per-photon statistics of the energy books (PhotonTally): accumulators for each part of the
// launched power, over the photons added.
struct PhotonStats {
  enum Part { kSpecular, kExited, kAbsorbed, kRoulette, kLost, kExitExcess, kParts };
  std::array<MeanAccumulator, kParts> part;
  uint64_t photons = 0, scatterings = 0, reflections = 0;

  void add(const PhotonTally& photon) {
    const double values[kParts] = {photon.specular, photon.exited,
                                   photon.absorbed, photon.roulette_loss - photon.roulette_gain,
                                   photon.lost,     photon.expected_exit_excess};
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
    MeanEstimate* out[kParts] = {&f.specular, &f.exited, &f.absorbed,
                                 &f.roulette, &f.lost,   &f.expected_exit_excess};
    double sum = 0;
    for (int k = 0; k < kParts; ++k) {
      *out[k] = part[k].estimate(photons);
      if (k != kExitExcess) sum += out[k]->mean;
    }
    sum -= f.expected_exit_excess.mean;
    f.energy_imbalance = photons == 0 ? 0.0 : 1.0 - sum;
    f.photons = photons;
    f.scatterings = scatterings;
    f.reflections = reflections;
    return f;
  }
};

// A batch whose items are photons: progress reports the stage "photons".
inline TaskBatch photon_batch(TaskBatch b) {
  b.stage = "photons";
  return b;
}

}  // namespace weft
