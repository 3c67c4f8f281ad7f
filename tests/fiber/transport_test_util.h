#pragma once
// Helpers shared by the photon-transport and fiber-bake tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "weft/core/error.h"
#include "weft/fiber/fiber_bake.h"
#include "weft/fiber/transport_batch.h"

namespace weft::testing {

// Batch options for a test run of 'photons' photons in tasks of 'photons_per_task'.
inline TaskBatch batch_options(uint64_t photons, uint64_t seed, int threads,
                               uint64_t photons_per_task) {
  TaskBatch b;
  b.items = photons;
  b.seed = seed;
  b.threads = threads;
  b.items_per_task = photons_per_task;
  return b;
}

// Settings of a one-band fiber bake (seed 1).
inline FiberBakeSettings bake_settings(int resolution, uint64_t photons, int threads = 2) {
  FiberBakeSettings s;
  s.resolution = resolution, s.photons = photons, s.seed = 1, s.threads = threads;
  return s;
}

// A homogeneous medium with a Henyey-Greenstein phase function.
inline TransportMedium hg_medium(double mu_a, double mu_s, double g, double n) {
  return {.mu_a = mu_a, .mu_s = mu_s, .n = n, .phase = PhaseFunction::henyey_greenstein(g)};
}

// The message of the weft::Error that f() throws, or "" when it throws none.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// |measured - reference| <= k * standard error (the reference's own error added in quadrature).
inline ::testing::AssertionResult within_sigma(const MeanEstimate& e, double reference, double k,
                                               double reference_error = 0) {
  const double se = std::sqrt(e.std_error * e.std_error + reference_error * reference_error);
  const double dev = std::abs(e.mean - reference);
  if (se > 0 && dev <= k * se) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "measured " << e.mean << " +- " << e.std_error << ", reference " << reference << " +- "
         << reference_error << ": " << dev / se << " sigma";
}

}  // namespace weft::testing
