// The ray trace's optional estimators (fabric/fabric_raytrace.h): the next-event estimate of the
// exits with the launch lattice (--estimator nee) and the light passing straight through computed
// rather than sampled (--straight-through exact): unbiased against the plain estimator, honest in
// their noise, reciprocal, energy-conserving and deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flat_sheet.h"
#include "raytrace_test_util.h"
#include "test_util.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/table_compare.h"
#include "weft/scenes/weave.h"

using namespace weft;
using namespace weft::testing;

// --- The next-event estimate of the exits and the launch lattice (FabricRaytraceOptions
// next_event_rays, launch_lattice: weft bake fabric --estimator nee).

namespace {

FabricRaytraceOptions nee_options(int resolution, uint64_t particles_per_bin) {
  FabricRaytraceOptions o = options(resolution, particles_per_bin);
  o.next_event_rays = 2;
  o.launch_lattice = 13;
  return o;
}

// A coloured table whose channels differ in shape, not only in scale: the hero's MIS weights
// matter (the proposal test's shape, with a transmitted lobe).
TabulatedBsdfTable coloured_fiber(int resolution) {
  return fiber_table3(resolution, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double shape = (wo.z > 0 ? 1.0 : 0.3) * (1 + 0.5 * wo.z * wi.z) * kInvPi;
    v[0] = 0.3 * shape, v[1] = 0.15 * shape * (0.5 + wo.x * wo.x), v[2] = 0.08 * shape;
  });
}

}  // namespace

TEST(FabricRaytrace, NextEventEstimateIsUnbiased) {
  // The next-event estimate and the particles' own exits estimate the same table: cell by cell
  // against each other's stated standard errors (different seeds), with the proposal test's
  // bounds (z rms about 1, almost none beyond 4), for a reciprocal and a coloured fiber (the
  // hero's MIS weights per channel), at fiber and yarn detail (light passing its own tube).
  const std::pair<const char*, TabulatedBsdfTable> cases[] = {
      {"fiber", reciprocal_fiber(4)}, {"fiber", coloured_fiber(4)}, {"yarn", coloured_fiber(4)}};
  for (const auto& [detail, fiber] : cases) {
    const auto exits = raytrace_fabric_table(default_sample(detail), fiber, options(3, 6000));
    FabricRaytraceOptions o = nee_options(3, 3000);
    o.seed = 2;
    const auto nee = raytrace_fabric_table(default_sample(detail), fiber, o);
    EXPECT_EQ(nee.table.metadata.at("next_event_rays"), "2");
    const ZStats z = z_scores(nee, exits, [](int i, int k) { return std::pair{i, k}; });
    EXPECT_GT(z.cells, 200u) << detail;
    EXPECT_NEAR(z.rms, 1.0, 0.25) << detail;
    EXPECT_LT(z.beyond4, 0.01) << detail;
    // The books still close: exited is what the particles took out of the slab.
    EXPECT_NEAR(nee.exited + nee.absorbed + nee.lost + nee.roulette_net, 1.0, 1e-9) << detail;
  }
}

TEST(FabricRaytrace, NextEventEstimateIsReciprocalAndItsNoiseHonest) {
  // Reciprocity as TablesAreReciprocalWithinTheirNoise checks it, and the stated noise against
  // the spread of two seeds as NoiseEstimateMatchesTheSpreadOfIndependentRuns checks it (a launch
  // block's exits and next events are summed per cell before the variance is taken: the blocks,
  // not their particles, are the independent samples).
  const auto fiber = reciprocal_fiber(4);
  const auto a = raytrace_fabric_table(default_sample("fiber"), fiber, nee_options(3, 3000));
  const ZStats z = z_scores(a, a, [](int i, int k) { return std::pair{k, i}; });
  EXPECT_GT(z.cells, 200u);
  EXPECT_NEAR(z.rms, 1.0, 0.25);
  EXPECT_LT(z.beyond4, 0.01);
  FabricRaytraceOptions o = nee_options(3, 3000);
  o.seed = 2;
  const auto b = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  const double measured = compare_tables(a.table, b.table).overall.rel_rms;
  const double stated =
      std::sqrt(a.relative_noise * a.relative_noise + b.relative_noise * b.relative_noise);
  EXPECT_NEAR(measured / stated, 1.0, 0.25) << measured << " vs " << stated;
}

TEST(FabricRaytrace, NextEventEstimateOfALosslessFabricConservesEnergy) {
  // The white furnace: the lossless fiber of EnergyAtMostOnePerIncidentBin, four seeds. Per
  // incident bin the table's albedo is 1 at most within its noise and close to it (a bin's
  // particles share 2002 / 13 directions, so a bin's albedo spreads more than the hero
  // estimator's: 0.93 to 0.95 at four bins of another count), 0.97 or more over all bins
  // (FiberLevelSampleLeaksNoEnergy: the grazing lines absorb under 0.5 %); the particles' own
  // exits (the books) are no longer what the table adds up, only its expectation.
  //
  // The standard errors are the seeds' spread, not the cells': a scattering's next event books
  // into many cells of its bin at once, so the cells' errors are correlated and their sum as
  // independent (bin_energy's sigma) understates a bin's spread, by a factor of 1.7 to 2.1 over
  // four sets of four seeds (2026-12-04; with one seed and that sum the worst of the 18 bins sat
  // 3.4 to 5.7 of it from the books, seed by seed, and this test failed on one machine). Over all
  // bins (independent: each has its own particles) the table's albedo is the books' within 4
  // standard errors of the seeds' spread; per bin within 5 of the spread pooled over the bins in
  // proportion to the cells' sum (the bins' own inflation differs around the pooled one: the z's
  // rms over the bins was 1.5 in that run).
  const auto fiber = uniform_fiber(4, 0.5 * kInvPi);
  constexpr int kSeeds = 4;
  std::vector<std::vector<BinEnergy>> e(kSeeds);
  for (int k = 0; k < kSeeds; ++k) {
    FabricRaytraceOptions o = nee_options(3, 2002);
    o.seed = uint64_t(k + 1);
    const auto r = raytrace_fabric_table(default_sample("fiber"), fiber, o);
    for (int i = 0; i < r.table.bins(); ++i) e[k].push_back(bin_energy(r, i));
  }
  const size_t bins = e[0].size();
  std::vector<double> albedo(bins), diff(bins), diff_var(bins), stated2(bins);
  for (size_t i = 0; i < bins; ++i) {
    for (int k = 0; k < kSeeds; ++k) {
      albedo[i] += e[k][i].albedo / kSeeds;
      diff[i] += (e[k][i].albedo - e[k][i].exited) / kSeeds;
      stated2[i] += e[k][i].sigma * e[k][i].sigma / kSeeds;
    }
    for (int k = 0; k < kSeeds; ++k)
      diff_var[i] += std::pow(e[k][i].albedo - e[k][i].exited - diff[i], 2) / (kSeeds - 1);
  }
  double all_diff = 0, all_var = 0, ratio2 = 0, mean = 0;
  for (size_t i = 0; i < bins; ++i) {
    all_diff += diff[i] / double(bins);
    all_var += diff_var[i] / kSeeds / double(bins * bins);
    ratio2 += diff_var[i] / stated2[i] / double(bins);
    mean += albedo[i] / double(bins);
  }
  EXPECT_NEAR(all_diff, 0.0, 4 * std::sqrt(all_var));
  // The cells' sum understates, and not by an order of magnitude.
  const double factor = std::sqrt(ratio2);
  EXPECT_GT(factor, 0.8);
  EXPECT_LT(factor, 3.0);
  for (size_t i = 0; i < bins; ++i) {
    const double se = factor * std::sqrt(stated2[i] / kSeeds);  // of the seeds' mean
    EXPECT_LE(albedo[i], 1 + 4 * se) << "bin " << i;
    EXPECT_GT(albedo[i], 0.9) << "bin " << i;
    EXPECT_NEAR(diff[i], 0.0, 5 * se) << "bin " << i;
  }
  EXPECT_GT(mean, 0.97);
  EXPECT_LE(mean, 1.01);
}

TEST(FabricRaytrace, NextEventEstimateIsBitIdenticalAtAnyThreadCountAndInPieces) {
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);
  FabricRaytraceOptions o = nee_options(2, 300);
  o.threads = 1;
  const WovenSample sample = default_sample("fiber");
  const auto a = raytrace_fabric_table(sample, fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(sample, fiber, o);
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_EQ(a.standard_error, b.standard_error);
  EXPECT_EQ(a.exited, b.exited);
  o.first_bin = 3;
  o.bin_count = 2;
  const auto piece = raytrace_fabric_table(sample, fiber, o);
  const size_t row = static_cast<size_t>(a.table.bins()) * 3;
  EXPECT_TRUE(std::equal(a.table.values.begin() + 3 * row, a.table.values.begin() + 5 * row,
                         piece.table.values.begin() + 3 * row));
  // The hero estimator's bits do not move with the option off (its default).
  const auto off = raytrace_fabric_table(sample, fiber, options(2, 300));
  EXPECT_NE(off.table.values, a.table.values);
  EXPECT_EQ(off.table.metadata.count("next_event_rays"), 0u);
  // Bad counts are refused by name.
  o.next_event_rays = kMaxNextEventRays + 1;
  EXPECT_THROW(raytrace_fabric_table(sample, fiber, o), Error);
  o.next_event_rays = 1;
  o.launch_lattice = 0;
  EXPECT_THROW(raytrace_fabric_table(sample, fiber, o), Error);
  o.launch_lattice = 1;
  o.channel_sampling = ChannelSampling::mean;
  EXPECT_THROW(raytrace_fabric_table(sample, fiber, o), Error);
}

// --- The light passing straight through, computed (FabricRaytraceOptions::straight_through,
// fabric/straight_through.h; weft bake fabric --straight-through).

namespace {

// Whether cell (i, o) is incident bin i's straight-through cell: the direction continued.
bool straight_cell(const DirectionGrid& g, int i, int o) {
  return g.bin_of(-g.bin_center(i)) == o;
}

FabricRaytraceOptions sampled(FabricRaytraceOptions o) {
  o.straight_through = StraightThrough::sampled;
  return o;
}

}  // namespace

TEST(FabricRaytrace, ExactStraightThroughIsUnbiased) {
  // The computed straight-through part and the sampled one estimate the same table: cell by cell
  // against each other's stated standard errors (different seeds), with the proposal test's
  // bounds (z rms about 1, almost none beyond 4), and every straight-through cell within 4 of
  // them, for a reciprocal and a coloured fiber, at fiber and yarn detail. The exact part is
  // exercised: its cells' standard errors are well below the sampled ones.
  const std::pair<const char*, TabulatedBsdfTable> cases[] = {
      {"fiber", reciprocal_fiber(4)}, {"fiber", coloured_fiber(4)}, {"yarn", coloured_fiber(4)}};
  for (const auto& [detail, fiber] : cases) {
    const auto old =
        raytrace_fabric_table(default_sample(detail), fiber, sampled(options(3, 8000)));
    FabricRaytraceOptions o = options(3, 8000);
    o.seed = 2;
    const auto exact = raytrace_fabric_table(default_sample(detail), fiber, o);
    EXPECT_EQ(exact.table.metadata.at("straight_through"), "exact");
    EXPECT_EQ(old.table.metadata.count("straight_through"), 0u);
    const ZStats z = z_scores(exact, old, [](int i, int k) { return std::pair{i, k}; });
    EXPECT_GT(z.cells, 200u) << detail;
    EXPECT_NEAR(z.rms, 1.0, 0.25) << detail;
    EXPECT_LT(z.beyond4, 0.01) << detail;
    const DirectionGrid g = old.table.grid();
    const int nc = old.table.channels;
    double se_exact = 0, se_old = 0;
    for (int i = 0; i < g.bins(); ++i)
      for (int k = 0; k < g.bins(); ++k) {
        if (!straight_cell(g, i, k)) continue;
        for (int c = 0; c < nc; ++c) {
          const size_t v = old.table.index(i, k, c);
          const double sa = exact.standard_error[v], sb = old.standard_error[v];
          EXPECT_LT(std::abs(exact.table.values[v] - old.table.values[v]),
                    4 * std::sqrt(sa * sa + sb * sb))
              << detail << " cell " << i << ", " << k << " channel " << c;
          se_exact += sa, se_old += sb;
        }
      }
    EXPECT_LT(se_exact, 0.9 * se_old) << detail;
    // The books are the particles' (they still fly the light that meets nothing): they close.
    EXPECT_NEAR(exact.exited + exact.absorbed + exact.lost + exact.roulette_net, 1.0, 1e-9);
  }
}

TEST(FabricRaytrace, ExactStraightThroughNoiseMatchesTheSpreadOfIndependentRuns) {
  // As NoiseEstimateMatchesTheSpreadOfIndependentRuns checks the particles' noise: two seeds
  // differ by the two stated noises combined (the exact part's variance from its replicates
  // included), overall and channel by channel, within 25 %; and the stated noise of the dim
  // channels, which the straight-through light's hit-or-miss dominates, is below the sampled
  // estimator's at the same count. (Not red's: in these wide bins (R = 3) much of the bright red
  // light scattered forwards lands in the straight-through cell too, and a particle books one or
  // the other: sampled, the two parts' covariance is negative and takes back some of the
  // straight-through part's variance. At R = 8 on red cotton red gains too: docs/PERFORMANCE.md.)
  const auto red = fiber_table3(4, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double s = wo.z > 0 ? (0.3 + 0.2 * std::max(0.0, wi.z)) * kInvPi : 0.1 * kInvPi;
    v[0] = 0.9 * s, v[1] = 0.2 * s * (wo.z > 0), v[2] = 0.1 * s;
  });
  FabricRaytraceOptions o = options(3, 4000);
  const auto a = raytrace_fabric_table(default_sample("fiber"), red, o);
  o.seed = 2;
  const auto b = raytrace_fabric_table(default_sample("fiber"), red, o);
  const auto old = raytrace_fabric_table(default_sample("fiber"), red, sampled(o));
  const double measured = compare_tables(a.table, b.table).overall.rel_rms;
  const double stated =
      std::sqrt(a.relative_noise * a.relative_noise + b.relative_noise * b.relative_noise);
  EXPECT_NEAR(measured / stated, 1.0, 0.25) << measured << " vs " << stated;
  const DirectionGrid g = a.table.grid();
  const auto d = g.cosine_weighted_areas();
  for (int c = 0; c < 3; ++c) {
    double diff2 = 0, ref2 = 0;
    for (int i = 0; i < g.bins(); ++i)
      for (int k = 0; k < g.bins(); ++k) {
        const size_t v = a.table.index(i, k, c);
        diff2 += d[i] * d[k] * std::pow(a.table.values[v] - b.table.values[v], 2);
        ref2 += d[i] * d[k] * std::pow(a.table.values[v], 2);
      }
    const double na = a.relative_noise_per_channel[c], nb = b.relative_noise_per_channel[c];
    EXPECT_NEAR(std::sqrt(diff2 / ref2) / std::sqrt(na * na + nb * nb), 1.0, 0.25)
        << "channel " << c;
    if (c > 0) {
      EXPECT_LT(b.relative_noise_per_channel[c], 0.9 * old.relative_noise_per_channel[c])
          << "channel " << c;
    }
  }
}

TEST(FabricRaytrace, ExactStraightThroughChangesOnlyTheStraightThroughCells) {
  // The particles fly as before (the exact part has streams of its own), so every cell but the
  // straight-through ones keeps its bits, and the books are the same; the straight-through cells
  // change. The same bits at one and two threads, and in pieces.
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);
  const WovenSample sample = default_sample("fiber");
  FabricRaytraceOptions o = options(2, 500);
  o.threads = 1;
  const auto exact = raytrace_fabric_table(sample, fiber, o);
  const auto old = raytrace_fabric_table(sample, fiber, sampled(o));
  EXPECT_EQ(exact.exited, old.exited);
  EXPECT_EQ(exact.scatterings, old.scatterings);
  const DirectionGrid g = exact.table.grid();
  int changed = 0;
  for (int i = 0; i < g.bins(); ++i)
    for (int k = 0; k < g.bins(); ++k)
      for (int c = 0; c < 3; ++c) {
        const size_t v = exact.table.index(i, k, c);
        if (straight_cell(g, i, k))
          changed += exact.table.values[v] != old.table.values[v];
        else
          EXPECT_EQ(exact.table.values[v], old.table.values[v]) << i << ", " << k;
      }
  EXPECT_EQ(changed, 3 * g.bins());
  o.threads = 2;
  const auto two = raytrace_fabric_table(sample, fiber, o);
  EXPECT_EQ(two.table.values, exact.table.values);
  EXPECT_EQ(two.standard_error, exact.standard_error);
  o.first_bin = 3;
  o.bin_count = 2;
  const auto piece = raytrace_fabric_table(sample, fiber, o);
  const size_t row = static_cast<size_t>(g.bins()) * 3;
  EXPECT_TRUE(std::equal(exact.table.values.begin() + 3 * row, exact.table.values.begin() + 5 * row,
                         piece.table.values.begin() + 3 * row));
  EXPECT_TRUE(std::equal(exact.standard_error.begin() + 3 * row,
                         exact.standard_error.begin() + 5 * row,
                         piece.standard_error.begin() + 3 * row));
}

TEST(FabricRaytrace, NoiseCostScalesTheRunToOnePercent) {
  // bake fabric --json's noise_cost: a run's CPU seconds and particles scaled by (noise / 1 %)^2.
  // Where the particles' noise dominates a channel (red here), the noise falls as
  // 1/sqrt(particles): runs at 1 000 and 4 000 particles per bin project the same particles for
  // 1 % within 25 %. Where the computed straight-through light's noise dominates (green and blue:
  // little of them is scattered), it falls faster (its randomized lattice), so the projection is an
  // upper bound: the smaller run's is not below the larger's. A channel without noise projects
  // nothing (null); a cost without CPU time or particles is refused by name.
  const auto red = fiber_table3(4, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double s = wo.z > 0 ? (0.3 + 0.2 * std::max(0.0, wi.z)) * kInvPi : 0.1 * kInvPi;
    v[0] = 0.9 * s, v[1] = 0.2 * s * (wo.z > 0), v[2] = 0.1 * s;
  });
  const auto small = raytrace_fabric_table(default_sample("fiber"), red, options(3, 1000));
  const auto large = raytrace_fabric_table(default_sample("fiber"), red, options(3, 4000));
  const auto a = noise_cost_summary(small.relative_noise_per_channel, 1000, 2.0);
  const auto b = noise_cost_summary(large.relative_noise_per_channel, 4000, 8.0);
  ASSERT_EQ(a.at("particles_per_bin_to_target").size(), 3u);
  for (int c = 0; c < 3; ++c) {
    const double n = small.relative_noise_per_channel[c];
    EXPECT_DOUBLE_EQ(a.at("cpu_seconds_to_target")[c].get<double>(), 2.0 * n * n / 1e-4);
    const double pa = a.at("particles_per_bin_to_target")[c].get<double>(),
                 pb = b.at("particles_per_bin_to_target")[c].get<double>();
    if (c == 0)
      EXPECT_NEAR(pa / pb, 1.0, 0.25) << pa << " vs " << pb;
    else
      EXPECT_GT(pa / pb, 0.9) << "channel " << c << ": " << pa << " vs " << pb;
  }
  const auto none = noise_cost_summary({0.02, 0.0}, 100, 1.0);
  EXPECT_DOUBLE_EQ(none.at("cpu_seconds_to_target")[0].get<double>(), 4.0);
  EXPECT_TRUE(none.at("cpu_seconds_to_target")[1].is_null());
  EXPECT_THROW(noise_cost_summary({0.02}, 100, 0.0), Error);
  EXPECT_THROW(noise_cost_summary({0.02}, 100, std::nan("")), Error);
  EXPECT_THROW(noise_cost_summary({0.02}, 0, 1.0), Error);
}
