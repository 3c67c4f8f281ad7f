// The ray-traced fabric estimator (fabric/fabric_raytrace.h): analytic cases, energy, its
// noise estimate, reciprocity and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "flat_sheet.h"
#include "raytrace_test_util.h"
#include "test_util.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/table_compare.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

using weft::testing::flat_sheet;
using namespace weft::testing;

}  // namespace

TEST(FabricRaytrace, FlatLambertSheetIsLambertian) {
  // A flat sheet whose "fiber" is Lambertian (rho / pi above the point) is a Lambertian surface:
  // the ray-traced table is rho / pi wherever light and view are above it, 0 elsewhere, within
  // its own noise estimate.
  const double rho = 0.6;
  const auto fiber = fiber_table(
      4, [&](const Vec3& wo, const Vec3& wi) { return wo.z > 0 && wi.z > 0 ? rho / kPi : 0.0; });
  FabricRaytraceOptions o = options(3, 20000);
  const auto r = raytrace_fabric_table(flat_sheet(), fiber, o);
  ASSERT_FALSE(r.cancelled);
  const DirectionGrid g = r.table.grid();
  const auto d = g.cosine_weighted_areas();
  for (int i = 0; i < g.bins(); ++i)
    for (int k = 0; k < g.bins(); ++k) {
      const double f = r.table.at(i, k, 0);
      if (!g.upper(i) || !g.upper(k)) {
        EXPECT_EQ(f, 0.0) << i << " " << k;
        continue;
      }
      // Per cell: N_i D_o / pi exits of equal weight, a binomial count.
      const double count = o.particles_per_bin * (d[i] / g.bin_solid_angle()) * d[k] / kPi;
      EXPECT_NEAR(f, rho / kPi, 5 * rho / kPi / std::sqrt(count)) << i << " " << k;
    }
  // Light from above comes back, rho of it; light from below meets the sheet's back, where its
  // table holds nothing: half of the incident bins, so rho / 2 of the power (to the Monte Carlo
  // spread of |cos theta_i| over the bins, 1e-3).
  EXPECT_NEAR(r.exited, 0.5 * rho, 2e-3);
}

TEST(FabricRaytrace, PeriodicRepeatLeaksNoEnergy) {
  // A lossless whole-fiber table (each point returns half of what its fiber intercepts, f =
  // 1 / (2 pi) into its outer hemisphere for any light) on the closed red-cotton yarn sample: every
  // line through a yarn crosses its surface twice, so each scattering keeps the weight, and all
  // the light leaves the cloth, through its faces, wrapping across the repeat's sides as often as
  // it must. Exited = 1 up to the particles the scattering cap stops.
  const auto fiber = uniform_fiber(4, 0.5 * kInvPi);
  FabricRaytraceOptions o = options(4, 2000);
  const auto r = raytrace_fabric_table(default_sample(), fiber, o);
  EXPECT_GT(r.wraps, 0u);
  EXPECT_NEAR(r.exited + r.absorbed + r.lost + r.roulette_net, 1.0, 1e-9);
  EXPECT_LT(r.lost, 0.01);
  // Nothing leaves through the repeat's sides unbooked: the books close above. A line that
  // crosses a tube's surface once (where the lens sections press on each other and at their sharp
  // edges) kept only that point's half before a tube crossing returned the fiber's line albedo
  // (0.4 % of the power here); none is lost now.
  EXPECT_LT(std::abs(r.absorbed), 0.005);
  EXPECT_NEAR(r.exited, 1.0, 0.01);
}

TEST(FabricRaytrace, NoiseEstimateMatchesTheSpreadOfIndependentRuns) {
  // Two runs with different seeds differ by sqrt(2) x the stated relative noise (weft compare's
  // rel_rms weighting), within 25 %. The particles' own noise: the light passing straight through
  // sampled too (the exact part's: ExactStraightThroughNoiseMatchesTheSpreadOfIndependentRuns).
  const auto fiber = fiber_table(4, [](const Vec3& wo, const Vec3& wi) {
    return wo.z > 0 ? (0.3 + 0.2 * std::max(0.0, wi.z)) * kInvPi : 0.0;
  });
  FabricRaytraceOptions o = options(3, 4000);
  o.straight_through = StraightThrough::sampled;
  const auto a = raytrace_fabric_table(default_sample(), fiber, o);
  o.seed = 2;
  const auto b = raytrace_fabric_table(default_sample(), fiber, o);
  const double measured = compare_tables(a.table, b.table).overall.rel_rms;
  const double stated =
      std::sqrt(0.5 * (a.relative_noise * a.relative_noise + b.relative_noise * b.relative_noise)) *
      std::sqrt(2.0);
  EXPECT_NEAR(measured / stated, 1.0, 0.25) << measured << " vs " << stated;
  // Channel by channel, for a fiber whose channels differ (a red fiber: bright red, dark green
  // and blue, relatively noisier): weft compare's rel_rms restricted to one channel.
  const auto red = fiber_table3(4, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double s = wo.z > 0 ? (0.3 + 0.2 * std::max(0.0, wi.z)) * kInvPi : 0.1 * kInvPi;
    v[0] = 0.9 * s, v[1] = 0.2 * s * (wo.z > 0), v[2] = 0.1 * s;
  });
  o.seed = 1;
  const auto ra = raytrace_fabric_table(default_sample(), red, o);
  o.seed = 2;
  const auto rb = raytrace_fabric_table(default_sample(), red, o);
  const DirectionGrid g = ra.table.grid();
  const auto d = g.cosine_weighted_areas();
  for (int c = 0; c < 3; ++c) {
    double diff2 = 0, ref2 = 0;
    for (int i = 0; i < g.bins(); ++i)
      for (int k = 0; k < g.bins(); ++k) {
        const size_t v = (static_cast<size_t>(i) * g.bins() + k) * 3 + c;
        diff2 += d[i] * d[k] * std::pow(ra.table.values[v] - rb.table.values[v], 2);
        ref2 += d[i] * d[k] * std::pow(ra.table.values[v], 2);
      }
    const double na = ra.relative_noise_per_channel[c], nb = rb.relative_noise_per_channel[c];
    const double stated_c = std::sqrt(na * na + nb * nb);
    EXPECT_NEAR(std::sqrt(diff2 / ref2) / stated_c, 1.0, 0.25) << "channel " << c;
  }
  // The channels' noises differ: the blue, dimmest and diffuse, is not the red's.
  EXPECT_GT(std::abs(ra.relative_noise_per_channel[2] / ra.relative_noise_per_channel[0] - 1), 0.1);
}

TEST(FabricRaytrace, BitIdenticalAtOneAndTwoThreads) {
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);
  FabricRaytraceOptions o = options(2, 500);
  o.threads = 1;
  const auto a = raytrace_fabric_table(default_sample(), fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(default_sample(), fiber, o);
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_EQ(a.exited, b.exited);
}

TEST(FabricRaytrace, FiberLevelSampleLeaksNoEnergy) {
  // The lossless whole-fiber table of PeriodicRepeatLeaksNoEnergy on the fiber-level sample: a
  // line through a round fiber crosses its surface at B' and B'' (where it leaves the cylinder),
  // each keeping half, and the particle then passes through its own fiber (other fibers occlude).
  // All light leaves through the cloth's faces; what little is absorbed is where a line grazes a
  // fiber (one crossing) or meets a fiber's end cap at the repeat's side.
  const auto fiber = uniform_fiber(4, 0.5 * kInvPi);
  FabricRaytraceOptions o = options(4, 2000);
  const auto r = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_GT(r.wraps, 0u);
  EXPECT_GT(r.scatterings, r.particles);  // light meets several fibers on its way
  EXPECT_NEAR(r.exited + r.absorbed + r.lost + r.roulette_net, 1.0, 1e-9);
  EXPECT_LT(std::abs(r.absorbed), 0.005);
  EXPECT_NEAR(r.exited, 1.0, 0.01);
}

namespace {

// The fiber-level trace of 'fiber' (R 2, 300 particles per bin) at one and at two threads, which
// must give the same bits; the two-thread result.
FabricRaytraceResult same_bits_at_one_and_two_threads(const TabulatedBsdfTable& fiber) {
  FabricRaytraceOptions o = options(2, 300);
  o.threads = 1;
  const auto a = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_EQ(a.exited, b.exited);
  EXPECT_EQ(a.scatterings, b.scatterings);
  return b;
}

}  // namespace

TEST(FabricRaytrace, FiberLevelBitIdenticalAtOneAndTwoThreads) {
  same_bits_at_one_and_two_threads(uniform_fiber(3, 0.4 * kInvPi));
}

// A fiber table that names a surface lobe is traced with the lobe exact at fiber detail (the
// table's metadata says so), with the same bits at any thread count; at yarn detail the tubes'
// line albedo reads the cells, and so does the trace.
TEST(FabricRaytrace, AnExactSurfaceLobeTracesTheSameBitsAtOneAndTwoThreads) {
  auto fiber = uniform_fiber(3, 0.3 * kInvPi);
  fiber.add_surface_lobe(SurfaceLobe{{MicrofacetModel::kGgx, 0.1}, {1.6, 1.6, 1.6}}, 1);
  const auto a = same_bits_at_one_and_two_threads(fiber);
  EXPECT_EQ(a.table.metadata.at("fiber_surface_lobe"), "exact");
  const FabricRaytraceOptions o = options(2, 300);
  auto cells = fiber;
  cells.surface_lobe.reset();
  const auto c = raytrace_fabric_table(default_sample("fiber"), cells, o);
  EXPECT_NE(a.table.values, c.table.values);
  EXPECT_EQ(c.table.metadata.count("fiber_surface_lobe"), 0u);
  const auto yarn = raytrace_fabric_table(default_sample("yarn"), fiber, o);
  EXPECT_EQ(yarn.table.metadata.count("fiber_surface_lobe"), 0u);
}

TEST(FabricRaytrace, TablesAreReciprocalWithinTheirNoise) {
  // With a reciprocal fiber table the fabric's is reciprocal: f(wi, wo) = f(wo, wi). Cell pair
  // (i, o) against (o, i), each with its stated standard error: the z-scores have rms about 1
  // (the two cells are estimated from different particles) and almost none lie beyond 4.
  // At yarn detail, before light a tube sent into itself passed through it (it was scattered by
  // the same tube again) and before the table's frame on a tube was its facet's, z rms was 1.49
  // at 20 000 particles per bin (1.39 with the facet frame alone, 1.12 with the passing alone).
  const std::pair<const char*, uint64_t> cases[] = {{"fiber", 6000}, {"yarn", 20000}};
  for (const auto& [detail, particles] : cases) {
    const auto fiber = reciprocal_fiber(4);
    FabricRaytraceOptions o = options(3, particles);
    const auto r = raytrace_fabric_table(default_sample(detail), fiber, o);
    const ZStats z = z_scores(r, r, [](int i, int k) { return std::pair{k, i}; });
    EXPECT_GT(z.cells, 200u) << detail;
    EXPECT_NEAR(z.rms, 1.0, 0.25) << detail;
    EXPECT_LT(z.beyond4, 0.01) << detail;
    // This fiber sends light into itself (its table is 0.5 x below the point's tangent plane):
    // at yarn detail that light passes through its tube.
    if (std::string(detail) == "yarn") {
      EXPECT_GT(r.tube_passes, r.particles / 10) << detail;
    }
  }
}

// Paths drawn from a proposal table and weighted by f / f_proposal (likelihood-ratio reweighting,
// FabricRaytraceOptions::proposal) estimate the same fabric table: the reciprocal fiber above,
// traced directly and through a coloured proposal of another shape (nonzero wherever the fiber
// is), cell by cell against each other's stated standard errors, with the reciprocity test's
// bounds (z rms about 1, almost none beyond 4). A proposal equal to the table is the default
// estimator, bit for bit.
TEST(FabricRaytrace, ProposalReweightingIsUnbiased) {
  const auto fiber = reciprocal_fiber(4);
  const auto proposal = fiber_table3(4, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double shape = (wo.z > 0 ? 1.0 : 0.3) * (1 + 0.5 * wo.z * wi.z) * kInvPi;
    v[0] = 0.3 * shape, v[1] = 0.15 * shape, v[2] = 0.08 * shape;
  });
  FabricRaytraceOptions o = options(3, 6000);
  const auto direct = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  o.proposal = &fiber;
  const auto same = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_EQ(same.table.values, direct.table.values);
  o.proposal = &proposal;
  o.seed = 2;
  const auto reweighted = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_EQ(reweighted.table.metadata.at("proposal_checksum"), proposal.checksum());
  const ZStats z = z_scores(reweighted, direct, [](int i, int k) { return std::pair{i, k}; });
  EXPECT_GT(z.cells, 200u);
  EXPECT_NEAR(z.rms, 1.0, 0.25);
  EXPECT_LT(z.beyond4, 0.01);
  EXPECT_NEAR(reweighted.exited + reweighted.absorbed + reweighted.lost + reweighted.roulette_net,
              1.0, 1e-9);
  // A proposal that does not fit the table is refused by name.
  const auto coarse = reciprocal_fiber(3);
  o.proposal = &coarse;
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), fiber, o), Error);
}

TEST(FabricRaytrace, EnergyAtMostOnePerIncidentBin) {
  // The lossless fiber of FiberLevelSampleLeaksNoEnergy: per incident bin the table's albedo
  // sum_o f D_o (reflected and transmitted) is 1 at most, within its noise (the launched
  // |cos theta_i| averaged over the bin's particles), and close to it (no light is lost).
  const auto fiber = uniform_fiber(4, 0.5 * kInvPi);
  FabricRaytraceOptions o = options(3, 3000);
  const auto r = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  const DirectionGrid g = r.table.grid();
  const auto d = g.cosine_weighted_areas();
  for (int i = 0; i < g.bins(); ++i)
    for (int c = 0; c < 3; ++c) {
      double albedo = 0, var = 0;
      for (int k = 0; k < g.bins(); ++k) {
        const size_t v = (static_cast<size_t>(i) * g.bins() + k) * 3 + c;
        albedo += r.table.values[v] * d[k];
        var += std::pow(r.standard_error[v] * d[k], 2);  // cells as independent: an upper bound
      }
      EXPECT_LE(albedo, 1 + 4 * std::sqrt(var)) << "bin " << i << " channel " << c;
      EXPECT_GT(albedo, 0.95) << "bin " << i << " channel " << c;
    }
}

TEST(FabricRaytrace, PlainWeaveTurnedBy90DegreesSwapsWarpAndWeft) {
  // A: a plain weave (balanced crimp); B: the same with warp and weft sizes swapped, which is A
  // turned by 90 degrees about the normal (tests/scenes/test_woven.cpp). In the cloth frame the
  // turn is T(x, y, z) = (-y, x, z), so f_B(T wi, T wo) = f_A(wi, wo): the grid maps bins onto
  // bins under T (DirectionGrid's square turned by 90 degrees). Within the stated noise.
  WeaveOptions a = red_cotton_weave_options();
  a.warp_crimp_share = -1;
  a.warp_spacing_mm = 0.25, a.warp_width_mm = 0.22, a.warp_thickness_mm = 0.07;
  a.weft_spacing_mm = 0.50, a.weft_width_mm = 0.45, a.weft_thickness_mm = 0.15;
  WeaveOptions b = a;
  std::swap(b.warp_spacing_mm, b.weft_spacing_mm);
  std::swap(b.warp_width_mm, b.weft_width_mm);
  std::swap(b.warp_thickness_mm, b.weft_thickness_mm);
  const auto fiber = reciprocal_fiber(4);
  FabricRaytraceOptions o = options(3, 20000);
  const auto ra = raytrace_fabric_table(make_woven_sample(a), fiber, o);
  o.seed = 7;
  const auto rb = raytrace_fabric_table(make_woven_sample(b), fiber, o);
  const DirectionGrid g = ra.table.grid();
  std::vector<int> turned(g.bins());
  for (int k = 0; k < g.bins(); ++k) {
    const Vec3 c = g.bin_center(k);
    turned[k] = g.bin_of({-c.y, c.x, c.z});
    // T maps the bin's centre to another bin's centre.
    EXPECT_LT(length(g.bin_center(turned[k]) - Vec3{-c.y, c.x, c.z}), 1e-9) << k;
  }
  const ZStats z = z_scores(ra, rb, [&](int i, int k) { return std::pair{turned[i], turned[k]}; });
  EXPECT_GT(z.cells, 200u);
  EXPECT_NEAR(z.rms, 1.0, 0.25);
  EXPECT_LT(z.beyond4, 0.01);
  // Not trivially: the table is not symmetric under T by itself (warp and weft differ), so the
  // identity map fails the criterion the turned map passes above (z rms 1.49 here).
  const ZStats same = z_scores(ra, rb, [](int i, int k) { return std::pair{i, k}; });
  EXPECT_GT(same.rms, 1.25) << z.rms;
}

TEST(FabricRaytrace, NoFiberIsMetFromInside) {
  // Fibers end at the repeat's sides, where their continuation (the same fiber a period on) begins
  // with an end sphere that overlaps the fiber's; a particle leaving a fiber there through its body
  // starts inside it, and a B'' on the straight segment's cylinder beyond a bent fiber's segment
  // may lie inside a neighbour. The scene passes such rays through (RenderScene), so no hit comes
  // from inside but at ties of rounding (before: 281 per 400 000 scatterings here at R = 2).
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);
  FabricRaytraceOptions o = options(2, 3000);
  const auto r = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_GT(r.scatterings, 10000u);
  EXPECT_LT(r.inside_hits, 1e-5 * r.scatterings);
}

namespace {

// Albedo of one channel over all light and exit cells, weighted by the incident cells' D_i (the
// power-weighted mean of the fabric's albedo), and its standard error: per incident bin the cells'
// errors added as if independent (an upper bound: one particle reaches one cell at most).
std::pair<double, double> mean_albedo(const FabricRaytraceResult& r, int c) {
  const DirectionGrid g = r.table.grid();
  const auto d = g.cosine_weighted_areas();
  const int nc = r.table.channels;
  double sum = 0, var = 0, weight = 0;
  for (int i = 0; i < g.bins(); ++i) {
    double bin_var = 0;
    for (int k = 0; k < g.bins(); ++k) {
      const size_t v = (static_cast<size_t>(i) * g.bins() + k) * nc + c;
      sum += d[i] * d[k] * r.table.values[v];
      bin_var += std::pow(d[k] * r.standard_error[v], 2);
    }
    var += d[i] * d[i] * bin_var;
    weight += d[i];
  }
  return {sum / weight, std::sqrt(var) / weight};
}

}  // namespace

TEST(FabricRaytrace, ChannelsOfAStronglyColouredFiberAreAlikeInNoise) {
  // A red fiber of whole-fiber albedo about (0.9, 0.05, 0.05). Red leaves only from where a line
  // through the axis leaves the fiber (B'' with w_i within 26 degrees of the inward normal; point
  // albedo 3, the rest absorbed), as the bundled red cotton's table concentrates red (point albedo
  // up to 2.8 there, under 0.6 in green): a particle's red weight is multiplied by 3 or by 0 at
  // each fiber. Green and blue: 0.05 from where the line enters (B'), outwards. With spectral MIS,
  // roulette on the largest weight and splitting (the default) the channels' relative noises are
  // within a factor 3 of each other, and the estimator before it (steered by the channels' mean)
  // agrees on every channel's albedo within their noise: neither is biased. The particles'
  // sampling is what is checked: the light passing straight through sampled too (computed, it
  // leaves green and blue 3.1 times less noisy than red here, as it leaves the noise of the paths).
  const auto red = fiber_table3(4, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    v[0] = wi.z < -0.9 ? 3 * 0.5 * kInvPi : 0;               // albedo: f x 2 pi
    v[1] = v[2] = wi.z > 0 && wo.z > 0 ? 0.05 * kInvPi : 0;  // albedo: f x pi
  });
  FabricRaytraceOptions o = options(2, 3000);
  o.straight_through = StraightThrough::sampled;
  const auto mis = raytrace_fabric_table(default_sample("fiber"), red, o);
  o.channel_sampling = ChannelSampling::mean;
  o.seed = 2;
  const auto mean = raytrace_fabric_table(default_sample("fiber"), red, o);
  const auto& n = mis.relative_noise_per_channel;
  EXPECT_LT(*std::max_element(n.begin(), n.end()) / *std::min_element(n.begin(), n.end()), 3.0)
      << n[0] << " " << n[1] << " " << n[2];
  EXPECT_GT(mis.splits, 0u);
  for (int c = 0; c < 3; ++c) {
    const auto [m_mis, s_mis] = mean_albedo(mis, c);
    const auto [m_old, s_old] = mean_albedo(mean, c);
    EXPECT_GT(m_mis, 0) << "channel " << c;
    EXPECT_LT(std::abs(m_mis - m_old), 4 * std::hypot(s_mis, s_old))
        << "channel " << c << ": " << m_mis << " +- " << s_mis << " vs " << m_old << " +- "
        << s_old;
  }
  // The books still close.
  EXPECT_NEAR(mis.exited + mis.absorbed + mis.lost + mis.roulette_net, 1.0, 1e-9);
}

TEST(FabricRaytrace, SplitsAndRouletteKillsAreCountedPerIncidentBin) {
  // The red fiber of ChannelsOfAStronglyColouredFiberAreAlikeInNoise (point albedo 3 in red):
  // weights grow, so the hero estimator splits, and roulette ends dim paths. The counts per
  // incident bin add up to the totals, depend only on (seed, bin) (a run of some bins counts what
  // the whole run counts there), and a lower split threshold splits more; the mean estimator
  // never splits. The table's metadata names the estimator and its threshold.
  const auto red = fiber_table3(3, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    v[0] = wi.z < -0.9 ? 3 * 0.5 * kInvPi : 0;
    v[1] = v[2] = wi.z > 0 && wo.z > 0 ? 0.05 * kInvPi : 0;
  });
  const WovenSample sample = default_sample("fiber");
  FabricRaytraceOptions o = options(2, 1500);
  const auto whole = raytrace_fabric_table(sample, red, o);
  const int bins = DirectionGrid{2}.bins();
  ASSERT_EQ(whole.splits_per_bin.size(), static_cast<size_t>(bins));
  ASSERT_EQ(whole.roulette_kills_per_bin.size(), static_cast<size_t>(bins));
  uint64_t splits = 0, kills = 0;
  for (int b = 0; b < bins; ++b) splits += whole.splits_per_bin[b];
  for (int b = 0; b < bins; ++b) kills += whole.roulette_kills_per_bin[b];
  EXPECT_GT(whole.splits, 0u);
  EXPECT_GT(whole.roulette_kills, 0u);
  EXPECT_EQ(splits, whole.splits);
  EXPECT_EQ(kills, whole.roulette_kills);
  EXPECT_EQ(whole.table.metadata.at("estimator"), "hero");
  EXPECT_EQ(whole.table.metadata.at("split_threshold"), "1");
  EXPECT_EQ(whole.table.metadata.at("max_copies_per_particle"), "1024");

  FabricRaytraceOptions piece = o;
  piece.first_bin = 3, piece.bin_count = 4;
  const auto part = raytrace_fabric_table(sample, red, piece);
  for (int b = 0; b < bins; ++b) {
    const bool in = b >= 3 && b < 7;
    EXPECT_EQ(part.splits_per_bin[b], in ? whole.splits_per_bin[b] : 0u) << b;
    EXPECT_EQ(part.roulette_kills_per_bin[b], in ? whole.roulette_kills_per_bin[b] : 0u) << b;
  }

  for (int bad : {0, -3, (1 << 20) + 1}) {
    FabricRaytraceOptions b = o;
    b.max_copies_per_particle = bad;
    try {
      (void)raytrace_fabric_table(sample, red, b);
      ADD_FAILURE() << "copy cap " << bad << " accepted";
    } catch (const weft::Error& e) {
      EXPECT_NE(std::string(e.what()).find("max_copies_per_particle"), std::string::npos);
    }
  }

  o.split_threshold = 0.25;
  const auto eager = raytrace_fabric_table(sample, red, o);
  EXPECT_GT(eager.splits, 2 * whole.splits);
  EXPECT_EQ(eager.table.metadata.at("split_threshold"), "0.25");

  o.channel_sampling = ChannelSampling::mean;
  const auto mean = raytrace_fabric_table(sample, red, o);
  EXPECT_EQ(mean.splits, 0u);
  EXPECT_GT(mean.roulette_kills, 0u);
  EXPECT_EQ(mean.table.metadata.at("estimator"), "mean");
  EXPECT_EQ(mean.table.metadata.count("split_threshold"), 0u);
}

// A table traced in pieces of incident bins (as `--shard` and `weft merge` do) has the whole run's
// rows, and its per-bin books summed by fabric_raytrace_totals give the whole run's energy books,
// counts and noise bit for bit: every total is a sum over bins in bin order. 300 particles per bin
// with tasks of up to 2048: tasks straddle the pieces' edges.
TEST(FabricRaytrace, PiecesAddUpToTheWholeRunsBooksAndNoise) {
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);  // lossy: every book is used
  const FabricRaytraceOptions o = options(2, 300);
  const WovenSample sample = default_sample("fiber");
  const auto whole = raytrace_fabric_table(sample, fiber, o);
  const int bins = DirectionGrid{2}.bins();
  FabricRaytraceResult pieces;
  pieces.table = whole.table;
  std::fill(pieces.table.values.begin(), pieces.table.values.end(), 0.0f);
  pieces.bin_books.resize(bins);
  for (const auto& [first, count] : {std::pair{0, 3}, std::pair{3, 1}, std::pair{4, bins - 4}}) {
    FabricRaytraceOptions p = o;
    p.first_bin = first;
    p.bin_count = count;
    const auto r = raytrace_fabric_table(sample, fiber, p);
    const size_t row = static_cast<size_t>(bins) * fiber.channels;
    for (int a = first; a < first + count; ++a) {
      std::copy(r.table.values.begin() + a * row, r.table.values.begin() + (a + 1) * row,
                pieces.table.values.begin() + a * row);
      pieces.bin_books[a] = r.bin_books[a];
    }
  }
  fabric_raytrace_totals(pieces);
  EXPECT_EQ(pieces.table.values, whole.table.values);
  EXPECT_EQ(pieces.exited, whole.exited);
  EXPECT_EQ(pieces.absorbed, whole.absorbed);
  EXPECT_EQ(pieces.lost, whole.lost);
  EXPECT_EQ(pieces.roulette_net, whole.roulette_net);
  EXPECT_EQ(pieces.relative_noise, whole.relative_noise);
  EXPECT_EQ(pieces.relative_noise_per_channel, whole.relative_noise_per_channel);
  EXPECT_EQ(pieces.particles, whole.particles);
  EXPECT_EQ(pieces.scatterings, whole.scatterings);
  EXPECT_EQ(pieces.splits, whole.splits);
  EXPECT_EQ(pieces.roulette_kills, whole.roulette_kills);
  EXPECT_EQ(pieces.splits_per_bin, whole.splits_per_bin);
  EXPECT_EQ(pieces.particles, uint64_t(300) * bins);
  EXPECT_GT(whole.relative_noise, 0.0);
}

TEST(FabricRaytrace, ColouredFiberFinishesWithBoundedCopiesPerParticle) {
  // A fiber that keeps half, 0.3 and 0.1 of the light at every point (outer hemisphere): the
  // channels' weights part along a path and splitting makes copies. Splitting is optional, so each
  // particle's copies are capped (here 64, to keep the test short): at most 63 per particle, a
  // finite table.
  const auto lossy = fiber_table3(2, [](const Vec3& wo, const Vec3&, std::span<double> v) {
    v[0] = wo.z > 0 ? 0.5 * kInvPi : 0;
    v[1] = wo.z > 0 ? 0.3 * kInvPi : 0;
    v[2] = wo.z > 0 ? 0.1 * kInvPi : 0;
  });
  FabricRaytraceOptions o = options(2, 300);
  o.max_copies_per_particle = 64;
  const WovenSample sample = default_sample("fiber");
  const auto r = raytrace_fabric_table(sample, lossy, o);
  EXPECT_EQ(r.particles, uint64_t(300) * DirectionGrid{2}.bins());
  EXPECT_LE(r.splits, 63 * r.particles);
  for (float v : r.table.values) ASSERT_TRUE(std::isfinite(v));
}

// A fiber sends out at most the light that hits it: total albedo (the bake's exit fraction) at
// most 1. The same 0.5 / pi on both hemispheres has total albedo 2 in red: the weights double at
// each crossing, and before this check the trace ran until they overflowed (with the copies
// capped) or did not end in 10 minutes (without). Now it is refused before any work, naming the
// table (as the traced fiber or as the proposal) and its albedo. The lossless classic fiber
// (reflectance 1: total albedo 1 by construction, materials/classic_fiber.h) tabulates within the
// trace's allowance of 1 % and is traced.
TEST(FabricRaytrace, EnergyCreatingFiberTablesAreRefusedBeforeAnyWork) {
  const auto creating = fiber_table3(2, [](const Vec3&, const Vec3&, std::span<double> v) {
    v[0] = 0.5 * kInvPi, v[1] = 0.3 * kInvPi, v[2] = 0.1 * kInvPi;
  });
  const auto albedo = creating.total_albedo();
  EXPECT_NEAR(albedo[0], 2.0, 1e-5);  // (1 / pi) (2 pi) (2 pi) (0.5 / pi)
  EXPECT_NEAR(albedo[1], 1.2, 1e-5);
  const WovenSample sample = default_sample("fiber");
  const FabricRaytraceOptions o = options(2, 300);
  const std::string as_fiber =
      weft::testing::error_of([&] { (void)raytrace_fabric_table(sample, creating, o); });
  EXPECT_NE(as_fiber.find("fiber"), std::string::npos) << as_fiber;
  EXPECT_NE(as_fiber.find("total albedo is 2 in channel 0"), std::string::npos) << as_fiber;
  const auto lossless = uniform_fiber(2, 0.5 * kInvPi);  // outer hemisphere: total albedo 1
  EXPECT_NEAR(lossless.total_albedo()[0], 1.0, 1e-5);
  FabricRaytraceOptions with_proposal = o;
  with_proposal.proposal = &creating;
  const std::string as_proposal = weft::testing::error_of(
      [&] { (void)raytrace_fabric_table(sample, lossless, with_proposal); });
  EXPECT_NE(as_proposal.find("proposal"), std::string::npos) << as_proposal;
  EXPECT_NE(as_proposal.find("total albedo"), std::string::npos) << as_proposal;

  const auto classic = weft::classic_fiber_table(
      weft::Rgb(1.0), {weft::MicrofacetModel::kBeckmann, 0.35}, 1.557, 2, 4, 1, 0);
  for (double a : classic.total_albedo()) {
    EXPECT_GT(a, 0.97);
    EXPECT_LT(a, 1.01);
  }
  const auto r = raytrace_fabric_table(sample, classic, o);
  for (float v : r.table.values) ASSERT_TRUE(std::isfinite(v));
}

TEST(FabricRaytrace, DirectionalAlbedoIsWhatTheBooksSayExitedInEveryIncidentBin) {
  // At every incident bin the table's directional albedo, sum_o f D_o reflected and transmitted,
  // is the fraction of the bin's launched power that its books say exited. Both add up the same
  // exits: the table divides them by the bin's expected launched power (particles x D_i / Omega,
  // the mean |cos theta_i| over the bin), the books by the power launched. So the table's albedo
  // times the expected launched power is the exited power booked, to the rounding of the table's
  // floats; and the two fractions differ only by the spread of the launched |cos theta_i| about its
  // mean, which the albedo's own standard error includes: they agree within 4 of it. A
  // normalization of the tally (the cells' solid angle, projected area or cosine), an exit counted
  // twice across the periodic wrap or a launch area of its own would part them. With the light
  // passing straight through computed (StraightThrough::exact) the table no longer adds up the
  // particles' own exits, only their expectation: the second holds, within 4 standard errors.
  for (const char* detail : {"yarn", "fiber"})
    for (const StraightThrough st : {StraightThrough::sampled, StraightThrough::exact}) {
      const auto fiber = clear_lossless_fiber(8);
      FabricRaytraceOptions o = options(3, 3000);
      o.straight_through = st;
      const auto r = raytrace_fabric_table(default_sample(detail), fiber, o);
      const DirectionGrid g = r.table.grid();
      const auto d = g.cosine_weighted_areas();
      for (int i = 0; i < g.bins(); ++i) {
        const BinEnergy e = bin_energy(r, i);
        const FabricBinBooks& b = r.bin_books[i];
        const double expected_launch = double(b.particles) * d[i] / g.bin_solid_angle();
        if (st == StraightThrough::sampled) {
          EXPECT_NEAR(e.albedo * expected_launch / b.exited, 1.0, 1e-5) << detail << " bin " << i;
        }
        EXPECT_NEAR(e.albedo, e.exited, 4 * e.sigma) << detail << " bin " << i;
        EXPECT_GT(e.sigma, 0) << detail << " bin " << i;
        EXPECT_LT(e.sigma, 0.05) << detail << " bin " << i;  // a test of some power
      }
    }
}

TEST(FabricRaytrace, ALosslessFiberCreatesNoEnergyInAnyIncidentBin) {
  // The clear lossless fiber above: at every incident bin at most the power launched exits,
  // within 4 standard errors of the bin's albedo, at yarn and at fiber detail. At yarn detail
  // every tube crossing returns the fiber's line albedo, about the tabulated fiber's total albedo
  // A (line_albedo.h), so a bin's particles keep A^k of their light after k crossings each on
  // average: that too, within 4 standard errors. The tubes used to return A' + A'' at their facets:
  // light along the normal meets both faces of the flattened lens head-on, as only lines through
  // a round fiber's axis do, and 1.27 of the light exited at normal incidence (11 standard errors
  // above 1), 0.62 at the most grazing bins. (At fiber detail a particle meets about 8 fibers, in
  // a packing that shades their edges; 0.84 to 1.07 exits.)
  for (const char* detail : {"yarn", "fiber"}) {
    const auto fiber = clear_lossless_fiber(8);
    const double total = fiber.total_albedo()[0];
    const auto r = raytrace_fabric_table(default_sample(detail), fiber, options(3, 3000));
    for (int i = 0; i < r.table.bins(); ++i) {
      const BinEnergy e = bin_energy(r, i);
      EXPECT_LE(e.exited, 1 + 4 * e.sigma) << detail << " bin " << i;
      const FabricBinBooks& b = r.bin_books[i];
      const double crossings = double(b.scatterings) / double(b.particles);
      if (std::string(detail) == "yarn") {
        EXPECT_NEAR(e.exited, std::pow(total, crossings), 4 * e.sigma) << detail << " bin " << i;
      }
    }
  }
}

namespace {

const std::string kWifDir = std::string(WEFT_SOURCE_DIR) + "/scenes/data/wif/";

// The scene's memory estimate (fabric_scene_bytes) grows with the sample and, for the bundled
// 84 x 100 draft at yarn detail (8.6 M triangles, weave_test's count), stays under 24 GB, the
// memory of the machine docs/PERFORMANCE.md measures on: the repeat's eight neighbours are
// instances, so they cost nothing per triangle. The estimate against measured peak RSS:
// scripts/fabric-memory.sh (docs/PERFORMANCE.md, "Memory of the fabric scene").
TEST(FabricSceneBytes, TheBundledLargeDraftFitsAtYarnDetail) {
  WeaveOptions o;
  o.wif = kWifDir + "8452.wif";
  const WovenSampleSize yarn = woven_sample_size(o);
  const double bytes = fabric_scene_bytes(yarn);
  EXPECT_LT(bytes, 24e9);
  // More than the sample's own vertices and triangles: an estimate, not a floor of zero.
  EXPECT_GT(bytes, yarn.vertices * 48 + yarn.triangles * 12);
  WeaveOptions coarse = o;
  coarse.sides = coarse.segments_per_crossing = 4;
  EXPECT_LT(fabric_scene_bytes(woven_sample_size(coarse)), bytes / 4);
}

// A short ray trace on the bundled 84 x 100 draft completes; at 4 sides and 4 segments per
// crossing (540 000 triangles) to keep the test short; the default tessellation's run is in
// docs/PERFORMANCE.md. Every particle is traced and some scatter.
TEST(FabricSceneBytes, AShortRayTraceOnTheLargeDraftCompletes) {
  WeaveOptions o;
  o.wif = kWifDir + "8452.wif";
  o.sides = o.segments_per_crossing = 4;
  const WovenSample s = make_woven_sample(o);
  ASSERT_EQ(s.summary.triangles, 2u * 8400 * 4 * 4 * 2);
  const auto fiber = uniform_fiber(2, 0.5 * kInvPi);
  const FabricRaytraceResult r = raytrace_fabric_table(s, fiber, options(1, 200));
  EXPECT_FALSE(r.cancelled);
  EXPECT_EQ(r.particles, 200u * DirectionGrid{1}.bins());
  EXPECT_GT(r.scatterings, 0u);
}

}  // namespace

// The sheen booked apart (FabricRaytraceOptions::sheen_h_resolution) at resolution R: the same
// paths as without (it draws no random number) and the same bits at any thread count. Returns the
// sheen's share of the reflected light, the light the cells (the rest plus the sheen's cell
// averages) lose against the plain table's relative to the sheen's, and the largest such change
// of one light bin's light relative to its sheen's.
struct SheenBooks {
  double share = 0, lost = 0, worst_bin = 0;
};
SheenBooks sheen_booked_apart(int resolution, int light_factor = 1, uint64_t samples = 2000,
                              SheenLight light = SheenLight::first_surface) {
  // A dark fiber with a bright surface (n 2.5: 18 % at normal incidence), so that the sheen is
  // much of what the cloth reflects.
  auto fiber = uniform_fiber(3, 0.02 * kInvPi);
  fiber.add_surface_lobe(SurfaceLobe{{MicrofacetModel::kGgx, 0.1}, {2.5, 2.5, 2.5}}, 1);
  FabricRaytraceOptions o = options(resolution, samples);
  const auto plain = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  o.sheen_h_resolution = 32, o.sheen_window = 8;
  o.sheen_light_resolution = light_factor * resolution;
  o.sheen_light = light;
  o.threads = 1;
  const auto a = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_TRUE(a.table.sheen && b.table.sheen);
  if (!a.table.sheen || !b.table.sheen) return {};
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_EQ(a.table.sheen->values, b.table.sheen->values);
  EXPECT_EQ(a.table.metadata.count("sheen_light"), light == SheenLight::reflected ? 1u : 0u);
  if (light_factor == 1) {  // finer light bins launch each bin's particles from them in turn
    EXPECT_EQ(a.exited, plain.exited);
    EXPECT_EQ(a.scatterings, plain.scatterings);
  }
  const TabulatedBsdfTable rest = a.table.without_sheen("");
  SheenBooks books;
  double sheen = 0, whole = 0;
  for (int bin = 0; bin < a.table.bins(); ++bin) {
    const auto with = a.table.directional_albedo(bin),
               without = plain.table.directional_albedo(bin);
    const auto r = rest.directional_albedo(bin);
    for (int c = 0; c < 3; ++c) {
      const double part = with.reflectance[c] - r.reflectance[c];
      sheen += part;
      whole += with.reflectance[c];
      books.lost += without.total(c) - with.total(c);
      if (part > 0.01 * with.reflectance[c])
        books.worst_bin =
            std::max(books.worst_bin, std::abs(without.total(c) - with.total(c)) / part);
    }
  }
  books.share = sheen / whole;
  books.lost /= sheen;
  return books;
}

// The sheen is much of the reflected light (over 10 %), and the cells with its cell averages lose
// less than 3 % of its light against the plain table's, no light bin more than 30 % of its own.
void expect_sheen_books_keep_the_light(const SheenBooks& books, const std::string& what) {
  std::printf("%s: sheen share %.3f, lost %.4f, worst bin %.3f\n", what.c_str(), books.share,
              books.lost, books.worst_bin);
  EXPECT_GT(books.share, 0.1) << what;
  EXPECT_LT(std::abs(books.lost), 0.03) << what;
  EXPECT_LT(books.worst_bin, 0.3) << what;
}

// Booked per (light bin, window bin) over the mean wi . h there, the sheen's cell averages carry
// the light the particles booked; what moves is the bilinear blend of Q between light bins.
// Measured: the sheen 16 % (R 2) and 15 % (R 4) of the reflected light; the cells' light 0.2 %
// and -2.7 % of the sheen's off the plain table's; one light bin's at most 15 % and 23 % of its
// sheen (the blend moves light between neighbouring bins). Booked as the sum of w / (wi . h) over
// the solid angle instead, the cells lost 31 % and 13 % of the sheen.
TEST(FabricRaytrace, TheSheenBookedApartKeepsTheLightOfEveryLightBin) {
  for (int resolution : {2, 4})
    expect_sheen_books_keep_the_light(sheen_booked_apart(resolution),
                                      "R " + std::to_string(resolution));
}

// Light bins of the sheen 2 and 4 times finer than the table's (R 2): each table bin's particles
// are launched from its nested light bins in turn, and each light bin's booking is over its own
// particles, so the cells still carry the light of every light bin. The plain table's paths are
// not the same here, so the two differ by their noise too: at R_l 8 and 8000 particles a bin (500
// a light bin) the lost light read -0.036, at 32000 0.016. Measured: lost 0.0015 (R_l 4, 8000) and
// 0.0157 (R_l 8, 32000); one light bin's at most 9 % and 8 % of its sheen.
TEST(FabricRaytrace, FinerSheenLightBinsKeepTheLightOfEveryLightBin) {
  for (int factor : {2, 4})
    expect_sheen_books_keep_the_light(sheen_booked_apart(2, factor, factor == 4 ? 32000 : 8000),
                                      "R_l " + std::to_string(2 * factor));
}

// Every reflected exit near the mirror booked into the sheen (SheenLight::reflected): the same
// paths as the plain table's at R_l = R, the cells less the light booked there, and the table
// says so. Measured (R 2, 8000 particles a bin): the sheen 21 % of the reflected light at R_l 2
// and 4; lost 0.0022 and 0.0060; one light bin's at most 7 % of its sheen.
TEST(FabricRaytrace, EveryReflectedExitNearTheMirrorBookedAsSheenKeepsTheLight) {
  for (int factor : {1, 2})
    expect_sheen_books_keep_the_light(sheen_booked_apart(2, factor, 8000, SheenLight::reflected),
                                      "reflected, R_l " + std::to_string(2 * factor));
}

TEST(FabricRaytrace, TheSheenNeedsTheExactLobeAndAWholeTable) {
  const auto fiber = uniform_fiber(3, 0.3 * kInvPi);  // no surface lobe
  FabricRaytraceOptions o = options(2, 10);
  o.sheen_h_resolution = 32, o.sheen_window = 8;
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), fiber, o), Error);
  auto lobed = fiber;
  lobed.add_surface_lobe(SurfaceLobe{{MicrofacetModel::kGgx, 0.1}, {1.6, 1.6, 1.6}}, 1);
  EXPECT_THROW(raytrace_fabric_table(default_sample("yarn"), lobed, o), Error);
  o.bin_count = 2;
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), lobed, o), Error);
  o.bin_count = 0, o.sheen_window = 40;
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), lobed, o), Error);
  // Light bins nest in the table's (2 or 4 times its resolution), each with a particle at least.
  o.sheen_window = 8, o.sheen_light_resolution = 6;
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), lobed, o), Error);
  o.sheen_light_resolution = 8;  // 16 light bins a table bin, 10 particles
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), lobed, o), Error);
  o.sheen_h_resolution = 0, o.sheen_light_resolution = 4;  // light bins without a sheen
  EXPECT_THROW(raytrace_fabric_table(default_sample("fiber"), lobed, o), Error);
}
