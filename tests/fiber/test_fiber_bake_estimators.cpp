// The fiber bake's estimator options against the plain bake: absorption as a weight, next-event
// estimation, mirror folding, surface samples and stratified entries estimate the same table, and
// their bits do not depend on the threads. Definitions: docs/fiber-bsdf.md.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <vector>

#include "chi2.h"
#include "fiber_bake_test_util.h"
#include "transport_test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/registry.h"
#include "weft/materials/tabulated_bsdf.h"

using namespace weft;

using namespace weft;
using namespace weft::testing;

TEST(FiberTableBake, AbsorptionWeightAgreesWithImplicitCaptureWithinStatisticalError) {
  const FiberSpec spec = test_spec(20, 0.10, 0.01);
  const MediumBand mb = compute_medium_band(spec, 16);
  const int k = 5;
  std::vector<double> exit[2], absorbed[2];
  CellStats st[2];
  for (int m = 0; m < 2; ++m) {
    const FiberBandPhysics ph =
        fiber_band_physics(spec, mb, 10'000'000, nullptr,
                           m == 0 ? WeightMode::implicit_capture : WeightMode::absorption_weight);
    FiberBakeSettings s = weft::testing::bake_settings(3, 40000, 2);
    st[m] = cell_stats(k, [&](uint64_t seed) {
      s.seed = seed + 100 * m;
      const FiberBandTable t = bake_fiber_band_direct(ph, s, nullptr);
      EXPECT_NEAR(t.energy_balance(), 1.0, 1e-12);
      if (m == 1) {
        EXPECT_EQ(t.roulette_net, 0.0);  // no roulette: it would decide on the weight
      }
      exit[m].push_back(t.exit_fraction);
      absorbed[m].push_back(t.absorbed_fraction);
      return t;
    });
  }
  EXPECT_LE(count_outliers(st[0].mean, st[0].se, st[1].mean, st[1].se, 4.5), 1);
  const auto mean_se = [](const std::vector<double>& v) {
    double s = 0, s2 = 0;
    for (double x : v) s += x, s2 += x * x;
    const double m = s / v.size();
    return std::pair{m, std::sqrt(std::max(0.0, s2 / v.size() - m * m) / (v.size() - 1))};
  };
  for (const auto* v : {exit, absorbed}) {
    const auto [a, sa] = mean_se(v[0]);
    const auto [b, sb] = mean_se(v[1]);
    EXPECT_GT(a, 0.05);
    EXPECT_NEAR(a, b, 4.5 * std::hypot(sa, sb)) << sa << " " << sb;
  }
}

TEST(FiberTableBake, NextEventEstimationAndMirrorFoldingEstimateThePlainTable) {
  const FiberSpec spec = test_spec(20, 0.10, 0.01);
  const MediumBand mb = compute_medium_band(spec, 16);
  const int k = 8;
  std::vector<double> exit[3], absorbed[3];
  CellStats st[3];           // plain, next-event, next-event folded
  const int resolution = 3;  // 324 cell pairs, about half of which receive light
  for (int m = 0; m < 3; ++m) {
    FiberBandPhysics ph =
        fiber_band_physics(spec, mb, 10'000'000, nullptr, WeightMode::implicit_capture,
                           m == 0 ? FiberExitEstimator::kPlain : FiberExitEstimator::kNextEvent);
    if (m == 2) ph.surface.samples = 4;
    FiberBakeSettings s = weft::testing::bake_settings(resolution, 40000, 2);
    st[m] = cell_stats(k, [&](uint64_t seed) {
      s.seed = seed + 100 * m;
      FiberBandTable t = bake_fiber_band_direct(ph, s, nullptr);
      EXPECT_NEAR(t.energy_balance(), 1.0, 1e-12);
      EXPECT_NEAR(fiber_table_energy(t) / kPi, t.exit_fraction, 1e-12);
      if (m == 0) {
        EXPECT_EQ(t.expected_exit_excess, 0.0);
      }
      if (m == 2) t.f = fold_fiber_mirror_symmetry(resolution, t.f);
      exit[m].push_back(t.exit_fraction);
      absorbed[m].push_back(t.absorbed_fraction);
      return t;
    });
  }
  for (int m = 1; m < 3; ++m)
    expect_same_table(st[0], st[m], exit[0], exit[m], absorbed[0], absorbed[m], m);
  // Lower noise: next-event estimation, and surface samples with mirror folding on top of it.
  EXPECT_LT(cell_noise(st[1]), 0.7 * cell_noise(st[0]));
  EXPECT_LT(cell_noise(st[2]), 0.5 * cell_noise(st[1]));
}

// The whole bake's defaults (next-event estimation, 4 surface samples, stratified entries, mirror
// folding), each band scaled to its walks' own exits (fiber_walk_energy_scale), against the plain
// bake, cell by cell over 8 seeds each: the scale's ratio bias (order 1/N) stays below the noise.
// The scale is checked to move the cells (else this would not test it), and the scaled table is
// no noisier than the unscaled one.
TEST(FiberTableBake, TheDefaultsScaledToTheWalksExitsEstimateThePlainTable) {
  const FiberSpec spec = test_spec(20, 0.10, 0.01);
  const int k = 8, resolution = 3, band = 16;
  std::vector<double> exit[3], absorbed[3];
  CellStats st[3];  // plain, the defaults scaled, the defaults unscaled
  double largest_change = 0;
  for (int m = 0; m < 3; ++m) {
    FiberTableBakeOptions o = fiber_bake_defaults(spec);
    o.resolution = resolution, o.threads = 2, o.passes = 2;
    o.photons_per_band = m == 0 ? 40000 : 10000;
    if (m == 0) {
      o.estimator = FiberExitEstimator::kPlain, o.surface_samples = 1;
      o.entry = FiberEntrySampling::kRandom;
    }
    st[m] = cell_stats(k, [&](uint64_t seed) {
      o.seed = seed + 100 * (m == 0);
      FiberBandWork work;
      work.first_band = band, work.last_band = band + 1;
      const FiberBandsResult r = trace_fiber_bands(spec, o, work);
      const FiberBandState& b = r.bands.at(0);
      const double n = static_cast<double>(b.photons);
      const double scale = m == 1 ? fiber_walk_energy_scale(b) : 1.0;
      if (m != 0)
        largest_change = std::max(largest_change, std::abs(fiber_walk_energy_scale(b) - 1));
      FiberBandTable t;
      t.f = fiber_band_averages(b, resolution, true, scale);
      exit[m].push_back((m == 1 ? b.exit - b.exit_excess : b.exit) / n);
      absorbed[m].push_back(b.absorbed / n);
      return t;
    });
  }
  expect_same_table(st[0], st[1], exit[0], exit[1], absorbed[0], absorbed[1], 1);
  EXPECT_GT(largest_change, 1e-3);
  EXPECT_LT(cell_noise(st[1]), 1.05 * cell_noise(st[2]));
}

TEST(FiberTableBake, StratifiedEntriesEstimateThePlainTable) {
  const FiberSpec spec = test_spec(20, 0.10, 0.01);
  const MediumBand mb = compute_medium_band(spec, 16);
  const int k = 8, resolution = 3;
  std::vector<double> exit[4], absorbed[4];
  // Random plain, stratified plain, stratified and random next-event with 4 surface samples.
  CellStats st[4];
  for (int m = 0; m < 4; ++m) {
    FiberBandPhysics ph =
        fiber_band_physics(spec, mb, 10'000'000, nullptr, WeightMode::implicit_capture,
                           m >= 2 ? FiberExitEstimator::kNextEvent : FiberExitEstimator::kPlain);
    if (m >= 2) ph.surface.samples = 4;
    FiberBakeSettings s = weft::testing::bake_settings(resolution, 40000, 2);
    s.entry = m == 0 || m == 3 ? FiberEntrySampling::kRandom : FiberEntrySampling::kStratified;
    st[m] = cell_stats(k, [&](uint64_t seed) {
      s.seed = seed + 100 * m;
      const FiberBandTable t = bake_fiber_band_direct(ph, s, nullptr);
      EXPECT_NEAR(t.energy_balance(), 1.0, 1e-12);
      EXPECT_NEAR(fiber_table_energy(t) / kPi, t.exit_fraction, 1e-12);
      exit[m].push_back(t.exit_fraction);
      absorbed[m].push_back(t.absorbed_fraction);
      return t;
    });
  }
  for (int m = 1; m < 4; ++m)
    expect_same_table(st[0], st[m], exit[0], exit[m], absorbed[0], absorbed[m], m);
  // With plain exits where a photon leaves is the noise, and stratifying its entry leaves the
  // total variance about as it was (0.97 of it here); with next-event estimation the entry's
  // randomness is much of what is left, and stratifying it lowers the variance (0.83 of it here;
  // docs/PERFORMANCE.md measures 1.5x fewer photons for the same error on red cotton).
  EXPECT_LT(cell_noise(st[1]), 1.1 * cell_noise(st[0]));
  EXPECT_LT(cell_noise(st[2]), 0.9 * cell_noise(st[3]));
}

TEST(FiberTableBake, StratifiedEntriesAreBitIdenticalAtAnyThreadCount) {
  FiberTableBakeOptions o{.resolution = 4, .photons_per_band = 300, .threads = 1, .passes = 2};
  o.entry = FiberEntrySampling::kStratified;
  o.surface_samples = 3;
  const auto a = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  o.threads = 3;
  const auto b = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  EXPECT_EQ(a.table.checksum(), b.table.checksum());
  EXPECT_EQ(a.table.metadata.at("entry"), "stratified");
  // A stratified entry is the direct route's; names are parsed strictly.
  o.route = FiberBakeRoute::kBssrdf;
  o.estimator = FiberExitEstimator::kPlain;
  EXPECT_NE(weft::testing::error_of([&] {
              bake_fiber_table(load_fiber_spec("red-cotton"), o);
            }).find("entry"),
            std::string::npos);
  EXPECT_THROW(parse_fiber_entry_sampling("sobol", "entry"), Error);
  EXPECT_EQ(parse_fiber_entry_sampling("stratified", "entry"), FiberEntrySampling::kStratified);
}

TEST(FiberTableBake, AbsorptionWeightMakesTheAlbedoSmoothInTheDyeAtAFixedSeed) {
  const FiberSpec spec = load_fiber_spec("red-cotton");
  const auto albedo_along_dye = [&](WeightMode mode) {
    std::vector<std::vector<double>> out;  // [step][band]
    for (int k = 0; k < 5; ++k) {
      FiberSpec dyed = spec;
      for (double& a : dyed.host_absorption_per_um) a *= 1 + 0.01 * k;
      for (auto& c : dyed.dyes) c.concentration_owf_percent *= 1 + 0.01 * k;  // its recipe's
      FiberTableBakeOptions o{.resolution = 4,
                              .photons_per_band = 2000,
                              .threads = 2,
                              .spectral = false,
                              .weight_mode = mode,
                              .passes = 1};
      const auto r = bake_fiber_table(dyed, o);
      std::vector<double> a;
      for (const auto& b : r.bands) a.push_back(b.exit_fraction);
      out.push_back(a);
    }
    return out;
  };
  // Violations of "decreasing and convex" along the steps, over the bands where the dye absorbs;
  // where it does not (710 nm: the measured Congo red table ends at 700 nm, fiber/data/dyes/
  // README.md) the albedo must not move at all.
  const Spectrum mu = host_total_absorption_per_um(spec);
  const auto violations = [&mu](const std::vector<std::vector<double>>& a) {
    int n = 0;
    for (size_t b = 0; b < a[0].size(); ++b)
      for (size_t k = 0; k + 1 < a.size(); ++k) {
        if (mu[b] == 0) {
          if (a[k + 1][b] != a[k][b]) ++n;
          continue;
        }
        if (!(a[k + 1][b] < a[k][b])) ++n;
        if (k + 2 < a.size() && a[k + 2][b] - 2 * a[k + 1][b] + a[k][b] < -1e-12) ++n;
      }
    return n;
  };
  const auto weighted = albedo_along_dye(WeightMode::absorption_weight);
  EXPECT_EQ(violations(weighted), 0);
  // Red-cotton's dye absorbs: the albedo does move with it. Its recipe (docs/presets.md) leaves
  // little but the surface's reflection at 450-550 nm, so it moves most where the fibre is half
  // absorbing, about 600 nm (band 21).
  EXPECT_LT(weighted[4][21], weighted[0][21] - 1e-3);
  // The contrast this mode exists for: the default's albedo along the same steps is not monotone.
  EXPECT_GT(violations(albedo_along_dye(WeightMode::implicit_capture)), 10);
}
