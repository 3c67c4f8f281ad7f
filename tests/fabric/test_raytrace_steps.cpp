// The steps of a particle's life in the fiber-level ray trace (fabric/raytrace_steps.h), one by
// one: launch, flight and the periodic wrap, the tube pass, crossings, scattering and its weights
// (a yarn tube's by the line albedo), the tally of an exit, Russian roulette and splitting.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "flat_sheet.h"
#include "weft/core/math.h"
#include "weft/fabric/fiber_sampler.h"
#include "weft/fabric/line_albedo.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/scenes/weave.h"

using namespace weft;
using namespace weft::raytrace;

namespace {

using weft::testing::flat_sheet;

// A repeat of 1 x 0.5 mm, 0.2 mm thick, centred on the origin.
RepeatSlab small_slab() {
  RepeatSlab s;
  s.px = 1e-3, s.pz = 0.5e-3;
  s.x0 = -0.5 * s.px, s.z0 = -0.5 * s.pz;
  s.y0 = -0.1e-3, s.y1 = 0.1e-3;
  return s;
}

WovenSample red_cotton(const char* detail) {
  WeaveOptions o;
  o.detail = detail;
  return make_woven_sample(overlay(red_cotton_weave_options(), o));
}

// A fiber table of resolution 2 and 'channels' channels holding value(i, o, c) in every cell.
template <class F>
TabulatedBsdfTable cell_table(F value, int channels = 3) {
  TabulatedBsdfTable t;
  t.resolution = 2;
  t.channels = channels;
  t.kind = "fiber";
  t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * channels, 0.0f);
  for (int i = 0; i < t.bins(); ++i)
    for (int o = 0; o < t.bins(); ++o)
      for (int c = 0; c < channels; ++c)
        t.values[t.index(i, o, c)] = static_cast<float>(value(i, o, c));
  return t;
}

// One crossing point whose light came from bin 'bin' of the fiber table.
Crossings one_point(int bin) {
  Crossings x;
  x.pts[0].bin = bin;
  x.count = 1;
  return x;
}

Particle particle_of_weight(double w0, const Strategies& st, bool proposal) {
  Launch l;
  l.w0 = w0;
  return launched_particle(l, 3, st, proposal);
}

}  // namespace

TEST(RaytraceSteps, LaunchEntersTheRepeatThroughTheFaceItFacesWithTheBinsDirection) {
  const DirectionGrid g{3};
  const RepeatSlab slab = small_slab();
  Rng rng(7, 0);
  double sum_x = 0, sum_z = 0;
  int n = 0;
  for (int bin = 0; bin < g.bins(); ++bin)
    for (int k = 0; k < 100; ++k, ++n) {
      const Launch l = launch(g, slab, bin, rng);
      // The light comes from a direction of its bin (cloth frame), towards the cloth.
      EXPECT_EQ(g.bin_of(world_to_cloth(-l.d)), bin);
      EXPECT_NEAR(length(l.d), 1.0, 1e-12);
      EXPECT_EQ(l.w0, std::abs(l.d.y));
      if (g.upper(bin)) {
        EXPECT_EQ(l.p.y, slab.y1);
        EXPECT_LT(l.d.y, 0);
      } else {
        EXPECT_EQ(l.p.y, slab.y0);
        EXPECT_GT(l.d.y, 0);
      }
      EXPECT_GE(l.p.x, slab.x0);
      EXPECT_LT(l.p.x, slab.x0 + slab.px);
      EXPECT_GE(l.p.z, slab.z0);
      EXPECT_LT(l.p.z, slab.z0 + slab.pz);
      sum_x += l.p.x, sum_z += l.p.z;
    }
  // Uniform over the repeat: the mean point is its centre (sd of a mean of n uniforms: P / sqrt(12
  // n), here 0.0068 P; bounds at 5 sd).
  EXPECT_NEAR(sum_x / n, 0.0, 0.034 * slab.px);
  EXPECT_NEAR(sum_z / n, 0.0, 0.034 * slab.pz);
}

TEST(RaytraceSteps, StrategiesFollowAHeroOnlyWithSpectralMis) {
  Rng rng(3, 0);
  const Strategies mean = draw_strategies(false, 3, rng);
  EXPECT_EQ(mean.count, 1);
  EXPECT_EQ(mean.hero, 3);  // the channels' mean
  EXPECT_EQ(mean.index(0), 3);
  EXPECT_EQ(mean.hero_slot(), 0);
  int heroes[3] = {0, 0, 0};
  for (int k = 0; k < 3000; ++k) {
    const Strategies st = draw_strategies(true, 3, rng);
    ASSERT_EQ(st.count, 3);
    ASSERT_GE(st.hero, 0);
    ASSERT_LT(st.hero, 3);
    EXPECT_EQ(st.index(2), 2);
    EXPECT_EQ(st.hero_slot(), st.hero);
    ++heroes[st.hero];
  }
  for (int h : heroes) EXPECT_NEAR(h, 1000, 150);  // uniform: sd 26
}

TEST(RaytraceSteps, BoundariesAheadFindTheSideOrTheFaceTheLineLeavesThrough) {
  const RepeatSlab slab = small_slab();  // x in +-0.5 mm, z in +-0.25 mm, y in +-0.1 mm
  const Vec3 o{0, 0, 0};
  Boundaries b = boundaries_ahead(slab, o, {1, 0, 0});
  EXPECT_EQ(b.side, 1);
  EXPECT_DOUBLE_EQ(b.t_side, 0.5e-3);
  EXPECT_TRUE(std::isinf(b.t_slab));
  b = boundaries_ahead(slab, o, {0, 0, -1});
  EXPECT_EQ(b.side, 2);
  EXPECT_DOUBLE_EQ(b.t_side, 0.25e-3);
  b = boundaries_ahead(slab, o, {-0.6, 0, 0.8});  // the z side comes first
  EXPECT_EQ(b.side, 3);
  EXPECT_DOUBLE_EQ(b.t_side, 0.25e-3 / 0.8);
  b = boundaries_ahead(slab, o, {0.6, -0.8, 0});  // the slab's lower face comes first
  EXPECT_EQ(b.side, 1);
  EXPECT_DOUBLE_EQ(b.t_slab, 0.1e-3 / 0.8);
  EXPECT_LT(b.t_slab, b.t_side);
  b = boundaries_ahead(slab, o, {0, 1, 0});
  EXPECT_EQ(b.side, -1);
  EXPECT_TRUE(std::isinf(b.t_side));
  EXPECT_DOUBLE_EQ(b.t_slab, 0.1e-3);
}

TEST(RaytraceSteps, PeriodicWrapReentersThroughTheOppositeSide) {
  const RepeatSlab slab = small_slab();
  const Vec3 p{0.1e-3, 0.02e-3, -0.05e-3};
  const Vec3 dirs[4] = {normalize(Vec3{-1, 0.1, 0.2}), normalize(Vec3{1, -0.1, 0.2}),
                        normalize(Vec3{0.2, 0.1, -1}), normalize(Vec3{-0.2, 0, 1})};
  for (int side = 0; side < 4; ++side) {
    const Vec3& d = dirs[side];
    const Boundaries b = boundaries_ahead(slab, p, d);
    ASSERT_EQ(b.side, side);
    const Vec3 out = p + b.t_side * d;  // where it leaves
    const Vec3 in = wrap_through_side(slab, p, d, b.t_side, side);
    // On the opposite side, the other coordinates kept.
    const double x_in = side == 0 ? slab.x0 + slab.px : side == 1 ? slab.x0 : out.x;
    const double z_in = side == 2 ? slab.z0 + slab.pz : side == 3 ? slab.z0 : out.z;
    EXPECT_NEAR(in.x, x_in, 1e-15) << side;
    EXPECT_NEAR(in.z, z_in, 1e-15) << side;
    EXPECT_EQ(in.y, out.y) << side;
    // Moved by exactly one period.
    EXPECT_NEAR(length(in - out), side < 2 ? slab.px : slab.pz, 1e-15) << side;
  }
}

TEST(RaytraceSteps, FiberAfterAWrapIsTheSameFiberInTheCopyThatLiesWhereItWas) {
  const int64_t curves = 10;
  const int64_t centre = copy_index(0, 0) * curves + 3;  // fiber 3 of the repeat itself
  // Leaving through +x the particle moves by -Px: the repeat's fiber is now in copy i = -1.
  EXPECT_EQ(fiber_after_wrap(centre, 1, curves), copy_index(-1, 0) * curves + 3);
  EXPECT_EQ(fiber_after_wrap(centre, 0, curves), copy_index(1, 0) * curves + 3);
  EXPECT_EQ(fiber_after_wrap(centre, 2, curves), copy_index(0, 1) * curves + 3);
  EXPECT_EQ(fiber_after_wrap(centre, 3, curves), copy_index(0, -1) * curves + 3);
  // A fiber of the copy at -x: through -x it is the repeat's own again; through +x it moves off
  // the tiling.
  const int64_t left = copy_index(-1, 1) * curves + 7;
  EXPECT_EQ(fiber_after_wrap(left, 0, curves), copy_index(0, 1) * curves + 7);
  EXPECT_EQ(fiber_after_wrap(left, 1, curves), kNoFiber);
  EXPECT_EQ(fiber_after_wrap(left, 2, curves), kNoFiber);
  EXPECT_EQ(fiber_after_wrap(kNoFiber, 0, curves), kNoFiber);
}

TEST(RaytraceSteps, FlightHitsTheSheetLeavesTheSlabOrWrapsAtTheSide) {
  const WovenSample sheet = flat_sheet();
  const RepeatSlab slab = repeat_slab_of(sheet);
  const RenderScene scene(tiled_geometry(sheet));
  Particle s;
  SurfaceHit h;
  s.p = {0, 0.04e-3, 0}, s.d = {0, -1, 0};
  ASSERT_EQ(fly(scene, slab, 0, s, &h), Flight::hit);
  EXPECT_NEAR(h.p.y, 0, 1e-12);
  EXPECT_NEAR(h.t, 0.04e-3, 1e-10);  // Embree: single precision
  s.d = {0, 1, 0};
  EXPECT_EQ(fly(scene, slab, 0, s, &h), Flight::left_slab);
  EXPECT_EQ(s.p.y, 0.04e-3);  // not moved
  // Almost level towards +x: the side of the repeat comes before the sheet.
  s.p = {0.4e-3, 0.04e-3, 0.1e-3}, s.d = normalize(Vec3{1, -0.01, 0});
  ASSERT_EQ(fly(scene, slab, 0, s, &h), Flight::wrapped);
  EXPECT_NEAR(s.p.x, slab.x0, 1e-15);
  EXPECT_NEAR(s.p.y, 0.04e-3 - 0.1e-3 * 0.01, 1e-12);
  EXPECT_EQ(s.p.z, 0.1e-3);
  // From there on it meets the sheet in the repeat (4 mm on, many wraps later).
  int wraps = 0;
  while (fly(scene, slab, 0, s, &h) == Flight::wrapped) ++wraps;
  EXPECT_EQ(wraps, 3);
  EXPECT_NEAR(h.p.y, 0, 1e-12);
  EXPECT_GE(h.p.x, slab.x0);
  EXPECT_LE(h.p.x, slab.x0 + slab.px);
}

TEST(RaytraceSteps, OnlyTheFarSideOfItsOwnTubePassesTheParticle) {
  SurfaceHit h;  // a tube's facet facing +y
  h.p = {0, 0, 0};
  h.ng = {0, 1, 0};
  h.offset = 1e-9;
  Particle s;
  s.d = {0, 1, 0};  // leaving the tube through this facet
  s.in_tube = true;
  EXPECT_TRUE(passes_own_tube(h, s));
  EXPECT_FALSE(s.in_tube);
  EXPECT_GT(s.p.y, 0);  // moved past the facet
  s.p = {};
  EXPECT_FALSE(passes_own_tube(h, s));  // not in a tube: scattered there
  s.in_tube = true, s.d = {0, -1, 0};   // entering another tube from outside
  EXPECT_FALSE(passes_own_tube(h, s));
  EXPECT_FALSE(s.in_tube);
  s.in_tube = true, s.d = {0, 1, 0};
  h.fiber = 5;  // a fiber, not a tube
  EXPECT_FALSE(passes_own_tube(h, s));
  EXPECT_EQ(s.p.y, 0);
}

TEST(RaytraceSteps, CrossingsOfAFiberAreWhereTheLineEntersAndLeavesIt) {
  const WovenSample sample = red_cotton("fiber");
  const RepeatSlab slab = repeat_slab_of(sample);
  const RenderScene scene(tiled_geometry(sample));
  const DirectionGrid fiber_grid{4};
  const Vec3 d = normalize(Vec3{0.3, -1, 0.2});
  int checked = 0;
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 8; ++k) {
      const Vec3 p{slab.x0 + slab.px * (i + 0.5) / 8, slab.y1, slab.z0 + slab.pz * (k + 0.5) / 8};
      SurfaceHit h;
      if (!scene.intersect({p, d, 1e300}, &h) || !h.on_fiber()) continue;
      const Crossings x = crossings_of(scene, h, d, fiber_grid);
      if (x.count < 2) continue;  // a graze
      ++checked;
      const FiberPoint& b1 = x.pts[0];
      const FiberPoint& b2 = x.pts[1];
      EXPECT_EQ(b2.hit.fiber, b1.hit.fiber);
      EXPECT_GT(b2.hit.t, b1.hit.t);
      EXPECT_LT(dot(d, b1.hit.ng), 0);  // enters
      EXPECT_GT(dot(d, b2.hit.ng), 0);  // leaves
      // The light comes from -d, above the first point's horizon, below the second's.
      EXPECT_GT(b1.wi_local.z, 0);
      EXPECT_LT(b2.wi_local.z, 0);
      EXPECT_EQ(b1.bin, fiber_grid.bin_of(b1.wi_local));
      EXPECT_FALSE(fiber_grid.upper(b2.bin));
    }
  EXPECT_GT(checked, 16);
}

TEST(RaytraceSteps, FiberSamplerDrawsDirectionsOfTheirCellWithTheTablesAlbedo) {
  const auto t = cell_table([](int i, int o, int c) { return (1 + c) * 0.01 * (1 + (i + o) % 3); });
  const FiberSampler fs(t);
  EXPECT_EQ(fs.strategies, 4);
  const int i = 5;
  double a[3] = {0, 0, 0};
  for (int o = 0; o < t.bins(); ++o)
    for (int c = 0; c < 3; ++c) a[c] += t.at(i, o, c) * fs.areas[o];
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fs.albedo_of(i, c), a[c], 1e-12 * a[c]);
  EXPECT_NEAR(fs.albedo_of(i, 3), (a[0] + a[1] + a[2]) / 3, 1e-12 * a[0]);
  EXPECT_NEAR(fs.value(i, 2, 3), (t.at(i, 2, 0) + t.at(i, 2, 1) + t.at(i, 2, 2)) / 3.0, 1e-9);
  Rng rng(5, 0);
  for (int b = 0; b < t.bins(); ++b)
    for (int k = 0; k < 20; ++k) EXPECT_EQ(fs.grid.bin_of(fs.cosine_direction_in(b, rng)), b);
}

TEST(RaytraceSteps, ScatteringDrawsOnlyWhereTheTableSendsLight) {
  // Light from every bin goes to cell 6 alone; from bin 1 nowhere (an absorbing point).
  const auto t = cell_table([](int i, int o, int) { return i != 1 && o == 6 ? 0.2 : 0.0; });
  const FiberSampler fs(t);
  Rng rng(11, 0);
  const Strategies st = draw_strategies(true, 3, rng);
  std::vector<double> s_sum(3);
  Crossings x = one_point(2);
  albedo_sums(fs, st, x, s_sum);
  for (int k = 0; k < 50; ++k) {
    const auto draw = draw_scatter(fs, st, x, s_sum, rng);
    ASSERT_TRUE(draw);
    EXPECT_EQ(draw->point, 0);
    EXPECT_EQ(draw->exit_bin, 6);
    EXPECT_EQ(fs.grid.bin_of(draw->wo_local), 6);
  }
  // B' absorbs everything: the hero always leaves from B''.
  x.pts[1] = x.pts[0];
  x.pts[0].bin = 1, x.count = 2;
  albedo_sums(fs, st, x, s_sum);
  for (int k = 0; k < 50; ++k) EXPECT_EQ(draw_scatter(fs, st, x, s_sum, rng)->point, 1);
  // Both absorb: nothing drawn, the stream untouched.
  x.pts[1].bin = 1;
  albedo_sums(fs, st, x, s_sum);
  Rng before = rng;
  EXPECT_FALSE(draw_scatter(fs, st, x, s_sum, rng));
  EXPECT_EQ(rng.uniform(), before.uniform());
}

TEST(RaytraceSteps, ScatteringWeightsAChannelByItsAlbedoWhateverTheHero) {
  // One crossing, channels of one shape and different strengths k_c: every strategy's step
  // density is f_j / S_j = f / A alike, so channel c's weight becomes w0 k_c A = w0 A_c, whichever
  // channel drew the path; the rest of the power is absorbed.
  const double k[3] = {0.9, 0.5, 0.1};
  const auto t = cell_table([&](int, int o, int c) { return k[c] * (o < 4 ? 0.3 : 0.05); });
  const FiberSampler fs(t);
  Rng rng(13, 0);
  const int bin = 3;
  for (int trial = 0; trial < 20; ++trial) {
    const Strategies st = draw_strategies(true, 3, rng);
    Particle s = particle_of_weight(0.7, st, false);
    std::vector<double> s_sum(3);
    const Crossings x = one_point(bin);
    albedo_sums(fs, st, x, s_sum);
    const auto draw = draw_scatter(fs, st, x, s_sum, rng);
    ASSERT_TRUE(draw);
    const double absorbed = weigh_scatter(fs, t, st, bin, draw->exit_bin, s_sum, s);
    double lost = 0;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(s.w[c], 0.7 * fs.albedo_of(bin, c), 1e-6 * s.w[c]) << c;
      lost += 0.7 - s.w[c];
      EXPECT_NEAR(s.pdf[c], 1.0, 1e-6);  // densities relative to their mean
    }
    EXPECT_NEAR(absorbed, lost / 3, 1e-12);
  }
}

TEST(RaytraceSteps, ASpectralTablesStrategiesAreThirdsOfItsBands) {
  // Seven bands: groups of three adjacent bands (the last of one), each drawn in proportion to
  // its bands' mean; an RGB table keeps a strategy per channel (the test above).
  const auto t =
      cell_table([](int i, int o, int c) { return 0.01 * (1 + c) * (1 + (i + o) % 3); }, 7);
  const FiberSampler fs(t);
  EXPECT_EQ(fs.groups, 3);
  EXPECT_EQ(fs.strategies, 4);
  EXPECT_EQ(fs.first_channel(1), 3);
  EXPECT_EQ(fs.last_channel(1), 6);
  EXPECT_EQ(fs.first_channel(2), 6);
  EXPECT_EQ(fs.last_channel(2), 7);
  const int i = 2, o = 5;
  EXPECT_NEAR(fs.value(i, o, 0), (t.at(i, o, 0) + t.at(i, o, 1) + t.at(i, o, 2)) / 3, 1e-9);
  EXPECT_DOUBLE_EQ(fs.value(i, o, 2), t.at(i, o, 6));
  double all = 0;
  for (int c = 0; c < 7; ++c) all += t.at(i, o, c);
  EXPECT_NEAR(fs.value(i, o, 3), all / 7, 1e-9);  // the mean strategy: every band
  double a = 0;
  for (int b = 0; b < t.bins(); ++b) a += fs.value(i, b, 1) * fs.areas[b];
  EXPECT_NEAR(fs.albedo_of(i, 1), a, 1e-12 * a);
}

TEST(RaytraceSteps, MisOverBandGroupsBooksEachBandsOwnTableInExpectation) {
  // Bands of unlike shapes inside one group: band 1 alone sends light to the cells from 4 on,
  // every other band only below 4 (band 6 alone in its group). A step's weight in band c, booked
  // in the cell it drew, has the expectation w0 f_c(o) D_o in every cell o, whichever group drew
  // it. A strategy that stood for its group by one band (band 0) would never draw band 1's cells.
  const auto t = cell_table(
      [](int, int o, int c) {
        if (c == 1) return o >= 4 ? 0.3 : 0.0;
        return o < 4 ? 0.05 * (1 + c) * (1 + o % 3) : 0.0;
      },
      7);
  const FiberSampler fs(t);
  const int bins = t.bins(), nc = 7, bin = 3, n = 200000;
  std::vector<double> sum(static_cast<size_t>(bins) * nc, 0.0), sum2(sum.size(), 0.0);
  Rng rng(29, 0);
  for (int k = 0; k < n; ++k) {
    const Strategies st = draw_strategies(true, fs.groups, rng);
    Particle s = particle_of_weight(1.0, st, false);
    s.w.assign(nc, 1.0);
    std::vector<double> s_sum(fs.groups);
    const Crossings x = one_point(bin);
    albedo_sums(fs, st, x, s_sum);
    const auto draw = draw_scatter(fs, st, x, s_sum, rng);
    ASSERT_TRUE(draw);
    weigh_scatter(fs, t, st, bin, draw->exit_bin, s_sum, s);
    for (int c = 0; c < nc; ++c) {
      sum[static_cast<size_t>(draw->exit_bin) * nc + c] += s.w[c];
      sum2[static_cast<size_t>(draw->exit_bin) * nc + c] += s.w[c] * s.w[c];
    }
  }
  for (int o = 0; o < bins; ++o)
    for (int c = 0; c < nc; ++c) {
      const size_t v = static_cast<size_t>(o) * nc + c;
      const double mean = sum[v] / n, se = std::sqrt(std::max(0.0, sum2[v] / n - mean * mean) / n);
      const double expected = t.at(bin, o, c) * fs.areas[o];
      EXPECT_NEAR(mean, expected, 5 * se + 1e-12) << "cell " << o << " band " << c;
    }
}

TEST(RaytraceSteps, UnderAProposalTheTracedWeightsFollowItsPathsTimesTheRatio) {
  // Paths drawn from a proposal P; the table traced is 0.5 P: its weights are half the proposal's
  // at every step (w = 0.5 w0 A_P, wp = w0 A_P, A_P the proposal's albedo).
  const auto proposal =
      cell_table([](int i, int o, int) { return 0.1 + 0.01 * ((i * 7 + o) % 5); });
  const auto traced = cell_table([&](int i, int o, int c) { return 0.5 * proposal.at(i, o, c); });
  const FiberSampler fs(proposal);
  Rng rng(17, 0);
  const Strategies st = draw_strategies(false, 3, rng);
  Particle s = particle_of_weight(1.0, st, true);
  std::vector<double> s_sum(1);
  const Crossings x = one_point(4);
  albedo_sums(fs, st, x, s_sum);
  const auto draw = draw_scatter(fs, st, x, s_sum, rng);
  ASSERT_TRUE(draw);
  weigh_scatter(fs, traced, st, 4, draw->exit_bin, s_sum, s);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(s.wp[c], fs.albedo_of(4, c), 1e-6);
    EXPECT_NEAR(s.w[c], 0.5 * s.wp[c], 1e-7);
  }
}

TEST(RaytraceSteps, LineAlbedoOfATableThatSeesOnlyTheHemisphereIsItsTwoSidesAlbedos) {
  // A' depends only on which side of the point the light comes from: every line returns
  // A(front) + A(behind), whatever its direction.
  const auto t = cell_table([](int i, int, int c) { return (i < 4 ? 0.1 : 0.04) * (1 + c); });
  const LineAlbedo line(t);
  const int front = 0, behind = 4;  // bins above and below the point's horizon
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(line.point(front, c), t.directional_albedo(front).total(c), 1e-12);
    const double expected = line.point(front, c) + line.point(behind, c);
    for (double axial : {-1.0, -0.7, 0.0, 0.3, 0.99, 1.0})
      EXPECT_NEAR(line.line(axial, c), expected, 1e-12 * expected) << axial << " " << c;
  }
}

TEST(RaytraceSteps, LineAlbedoUnderIsotropicLightIsTheTablesTotalAlbedo) {
  // Isotropic light brings each direction's lines in proportion to the fiber's projected width
  // sqrt(1 - s^2) (s the axial cosine, uniform over the sphere); every point of the fiber then
  // receives light from all directions (from behind through the fiber), so the fiber sends out
  // (1 / pi) sum_i A_i D_i of it: the total albedo. A table with no symmetry, whose A' + A''
  // varies along the lines.
  const auto t =
      cell_table([](int i, int o, int c) { return 0.02 + 0.03 * ((i * 5 + o * 3 + c) % 7); });
  const LineAlbedo line(t);
  const std::vector<double> total = t.total_albedo();
  for (int c = 0; c < 3; ++c) {
    double sum = 0, width = 0;
    const int steps = 4096;
    for (int k = 0; k < steps; ++k) {
      const double s = -1 + (k + 0.5) * 2.0 / steps, w = std::sqrt(1 - s * s);
      sum += w * line.line(s, c);
      width += w;
    }
    // The midpoint rules over u and s, of functions constant within the table's bins: 5e-6.
    EXPECT_NEAR(sum / width, total[c], 1e-4 * total[c]) << c;
  }
}

TEST(RaytraceSteps, ATubeCrossingReturnsTheLineAlbedo) {
  // After scattering at a tube's crossing, channel c's weight is scaled by L_c / S_c: the
  // crossing returns L_c of the light on average, where its facets returned S_c = A_c' + A_c''.
  // A channel that no facet returns stays as it is (nothing of it leaves there).
  const auto traced =
      cell_table([](int i, int, int c) { return c == 2 ? 0.0 : 0.05 * (1 + i % 3); });
  const auto proposal = cell_table([](int i, int, int) { return 0.04 + 0.01 * (i % 2); });
  const LineAlbedo line(traced), line_p(proposal);
  Crossings x;
  x.count = 2;
  x.pts[0].bin = 1, x.pts[1].bin = 6;
  const Vec3 axis = normalize(Vec3{1, 0.2, 0});
  x.pts[0].hit.shading = Frame::from_normal_tangent({0, 0, 1}, axis);
  const Vec3 d = normalize(Vec3{0.3, -0.2, -1});
  const double axial = dot(d, x.pts[0].hit.shading.s);
  Particle s;
  s.w = {0.8, 0.6, 0.4};
  s.wp = {0.5, 0.5, 0.5};
  const double absorbed = weigh_as_round_fiber(line, &line_p, x, d, s);
  double lost = 0;
  for (int c = 0; c < 3; ++c) {
    const double w0 = c == 0 ? 0.8 : c == 1 ? 0.6 : 0.4;
    const double s_c = line.point(1, c) + line.point(6, c);
    const double expected = s_c > 0 ? w0 * line.line(axial, c) / s_c : w0;
    EXPECT_NEAR(s.w[c], expected, 1e-12) << c;
    lost += w0 - s.w[c];
    const double sp = line_p.point(1, c) + line_p.point(6, c);
    EXPECT_NEAR(s.wp[c], 0.5 * line_p.line(axial, c) / sp, 1e-12) << c;
  }
  EXPECT_EQ(s.w[2], 0.4);
  EXPECT_NEAR(absorbed, lost / 3, 1e-12);
}

TEST(RaytraceSteps, LeavingAFiberStartsTheNewLineThere) {
  SurfaceHit h;
  h.p = {1, 2, 3};
  h.ng = {0, 0, 1};
  h.shading = Frame({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  h.offset = 1e-6;
  h.fiber = 42;
  Particle s;
  leave_fiber(h, normalize(Vec3{0.6, 0, 0.8}), s);
  EXPECT_NEAR(s.d.x, 0.6, 1e-15);
  EXPECT_NEAR(s.d.z, 0.8, 1e-15);
  EXPECT_GT(s.p.z, 3);  // off the surface on d's side
  EXPECT_EQ(s.ignore, 42);
  EXPECT_FALSE(s.in_tube);
  h.fiber = kNoFiber;  // a yarn tube: sent inwards, it is in its own tube
  leave_fiber(h, {0, 0, -1}, s);
  EXPECT_TRUE(s.in_tube);
  EXPECT_LT(s.p.z, 3);
}

TEST(RaytraceSteps, TallyPutsAnExitInItsCellAndMergesAParticlesExitsPerCell) {
  const DirectionGrid g{3};
  const int bins = g.bins();
  // Leaving along the centre of cloth bin 5 (world frame) from incident bin 2.
  const Vec3 d = cloth_to_world(g.bin_center(5));
  const uint64_t cell = exit_cell(g, 2, d);
  EXPECT_EQ(cell, 2u * bins + 5);
  EXPECT_EQ(exit_cell(g, 2, cloth_to_world(g.bin_center(bins - 1))), 2u * bins + bins - 1);
  Tally t;
  const std::vector<double> w1{1, 2, 3}, w2{0.5, 0.25, 0.125};
  tally_exit(t, 0, cell, w1);
  tally_exit(t, 0, cell + 1, w2);
  tally_exit(t, 0, cell, w2);  // the same particle again in the same cell: merged
  ASSERT_EQ(t.exits.size(), 2u);
  EXPECT_EQ(t.weights, (std::vector<double>{1.5, 2.25, 3.125, 0.5, 0.25, 0.125}));
  tally_exit(t, t.exits.size(), cell, w1);  // another particle: a record of its own
  ASSERT_EQ(t.exits.size(), 3u);
  EXPECT_EQ(t.exits[2].cell, cell);
  EXPECT_EQ(t.exits[2].first, 6u);
  // Books per incident bin, in the order the bins come.
  FabricBinBooks& b2 = t.books_of(2);
  b2.launched = 1;
  EXPECT_EQ(&t.books_of(2), &b2);
  t.books_of(3).launched = 2;
  ASSERT_EQ(t.books.size(), 2u);
  EXPECT_EQ(t.books[0].first, 2);
  EXPECT_EQ(t.books[1].second.launched, 2);
}

TEST(RaytraceSteps, RouletteKeepsTheExpectedWeight) {
  const Strategies st;
  Rng rng(19, 0);
  const std::vector<double> w0{0.01, 0.02, 0.03};
  const double threshold = 0.05, steer = 0.03, survive = steer / threshold;
  const int n = 20000;
  double sum[3] = {0, 0, 0};
  int survivors = 0;
  FabricBinBooks books;
  for (int k = 0; k < n; ++k) {
    Particle s = particle_of_weight(0, st, true);
    s.w = s.wp = w0;
    if (!survives_roulette(steer, threshold, 0.02, s, books, rng)) continue;
    ++survivors;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(s.w[c], w0[c] / survive);
      EXPECT_EQ(s.wp[c], w0[c] / survive);
      sum[c] += s.w[c];
    }
  }
  EXPECT_EQ(books.roulette_kills, static_cast<uint64_t>(n - survivors));
  // Survivors with probability 0.6: a binomial count, sd sqrt(n 0.6 0.4) = 69.
  EXPECT_NEAR(survivors, 0.6 * n, 5 * 69.3);
  // The expected weight is kept: sd of the mean w / 0.6 sqrt(0.6 0.4 / n) = 0.0058 w.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c] / n, w0[c], 5 * 0.0058 * w0[c]) << c;
  // The books' net: what the dead carried minus what the survivors gained; zero on average.
  EXPECT_NEAR(books.roulette_net / n, 0.0, 5 * 0.0058 * 0.02);
  // At or above the threshold nothing changes and nothing is drawn.
  Particle s = particle_of_weight(0.2, st, false);
  Rng before = rng;
  EXPECT_TRUE(survives_roulette(threshold, threshold, 0.2, s, books, rng));
  EXPECT_EQ(s.w, (std::vector<double>{0.2, 0.2, 0.2}));
  EXPECT_EQ(rng.uniform(), before.uniform());
}

TEST(RaytraceSteps, SteeringWeighsTheProposalsWeightsWhereThereIsOne) {
  Particle s;
  s.w = {0.3, 0.6, 0.9};
  Steering st = steering_of(s);
  EXPECT_DOUBLE_EQ(st.mean_w, 0.6);
  EXPECT_DOUBLE_EQ(st.mean_p, 0.6);
  EXPECT_EQ(st.max_w, 0.9);
  s.wp = {2, 1, 0};
  st = steering_of(s);
  EXPECT_DOUBLE_EQ(st.mean_w, 0.6);
  EXPECT_DOUBLE_EQ(st.mean_p, 1.0);
  EXPECT_EQ(st.max_w, 2);
}

TEST(RaytraceSteps, SplittingSharesTheWeightAmongItsCopies) {
  EXPECT_EQ(split_count(3.5, 1.0, 100), 4);
  EXPECT_EQ(split_count(100, 1.0, 100), kMaxSplit);
  EXPECT_EQ(split_count(3.5, 1.0, 2), 3);  // two more copies allowed
  EXPECT_EQ(split_count(1.5, 0.5, 100), 3);
  Particle s;
  s.p = {1, 2, 3}, s.events = 7, s.ignore = 12;
  s.w = {4, 2, 1}, s.wp = {8, 4, 2}, s.pdf = {0.5, 1, 1.5};
  std::vector<Particle> pending;
  split(s, 4, pending);
  ASSERT_EQ(pending.size(), 3u);
  EXPECT_EQ(s.w, (std::vector<double>{1, 0.5, 0.25}));
  EXPECT_EQ(s.wp, (std::vector<double>{2, 1, 0.5}));
  for (const Particle& c : pending) {
    EXPECT_EQ(c.w, s.w);
    EXPECT_EQ(c.wp, s.wp);
    EXPECT_EQ(c.pdf, s.pdf);  // densities are not split
    EXPECT_EQ(c.events, 7);
    EXPECT_EQ(c.ignore, 12);
    EXPECT_EQ(c.p.y, 2);
  }
}

TEST(RaytraceSteps, EscapeFollowsTheLineOutOfTheSlabOrStopsAtASurface) {
  const WovenSample sheet = flat_sheet();
  const RepeatSlab slab = repeat_slab_of(sheet);
  const RenderScene scene(tiled_geometry(sheet));
  Particle s;
  // Up from above the sheet, almost level: wraps through the sides, then leaves by the top face.
  s.p = {0.4e-3, 0.04e-3, 0.1e-3}, s.d = normalize(Vec3{1, 0.01, 0});
  const std::optional<Vec3> up = escape_direction(scene, slab, 0, s, 100);
  ASSERT_TRUE(up.has_value());
  EXPECT_EQ(up->y, s.d.y);
  // Down onto the sheet: stopped.
  s.p = {0, 0.04e-3, 0}, s.d = normalize(Vec3{1, -0.01, 0});
  EXPECT_FALSE(escape_direction(scene, slab, 0, s, 100).has_value());
  // Too few wraps allowed to reach the face: stopped too.
  s.p = {0.4e-3, 0.04e-3, 0.1e-3}, s.d = normalize(Vec3{1, 0.01, 0});
  EXPECT_FALSE(escape_direction(scene, slab, 0, s, 1).has_value());
}

TEST(RaytraceSteps, LatticePointsCoverTheRepeatEvenlyFromTheEntryPoint) {
  const RepeatSlab slab = small_slab();
  const Vec3 p{0.3e-3, slab.y1, -0.2e-3};
  EXPECT_NEAR(lattice_point(slab, p, 0, 13).x, p.x, 1e-15);
  EXPECT_NEAR(lattice_point(slab, p, 0, 13).z, p.z, 1e-15);
  // 13 points (a Fibonacci lattice, generator 8): every one of 13 columns and of 13 rows of the
  // repeat holds exactly one, at the entry point's offset in it; y is kept.
  std::vector<int> columns(13, 0), rows(13, 0);
  for (int m = 0; m < 13; ++m) {
    const Vec3 q = lattice_point(slab, p, m, 13);
    EXPECT_EQ(q.y, p.y);
    ASSERT_GE(q.x, slab.x0);
    ASSERT_LT(q.x, slab.x0 + slab.px);
    ASSERT_GE(q.z, slab.z0);
    ASSERT_LT(q.z, slab.z0 + slab.pz);
    const double fx = (q.x - slab.x0) / slab.px * 13, fz = (q.z - slab.z0) / slab.pz * 13;
    ++columns[static_cast<int>(fx)];
    ++rows[static_cast<int>(fz)];
    EXPECT_NEAR(fx - std::floor(fx), 0.8 * 13 - std::floor(0.8 * 13), 1e-9);  // p at x fraction 0.8
  }
  for (int k = 0; k < 13; ++k) EXPECT_EQ(columns[k], 1) << k;
  for (int k = 0; k < 13; ++k) EXPECT_EQ(rows[k], 1) << k;
  // Point 1 is one column and 8 rows on (mod 13).
  const Vec3 q1 = lattice_point(slab, p, 1, 13);
  EXPECT_NEAR((q1.x - p.x) / slab.px, 1.0 / 13, 1e-12);
  EXPECT_NEAR((q1.z - p.z) / slab.pz - std::floor((q1.z - p.z) / slab.pz), 8.0 / 13, 1e-12);
}

namespace {

// A fiber table that names a surface lobe (GGX 0.15, the last channel of another index) beside a
// smooth rest: more light above the point than below, by channel.
TabulatedBsdfTable table_with_lobe(int resolution) {
  TabulatedBsdfTable t = cell_table([](int, int, int) { return 0.0; });
  t.resolution = resolution;
  t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * 3, 0.0f);
  const DirectionGrid g = t.grid();
  for (int i = 0; i < t.bins(); ++i)
    for (int o = 0; o < t.bins(); ++o)
      for (int c = 0; c < 3; ++c)
        t.values[t.index(i, o, c)] =
            static_cast<float>((g.upper(o) ? 0.06 : 0.02) * (1 + 0.3 * c) * (1 + 0.2 * g.upper(i)));
  t.add_surface_lobe(SurfaceLobe{{MicrofacetModel::kGgx, 0.15}, {1.6, 1.6, 1.45}}, 1);
  return t;
}

}  // namespace

TEST(RaytraceSteps, AnExactSurfaceLobeBooksTheFibersFInExpectation) {
  // A step with the exact lobe (FiberSampler's lobe) from one exact light direction wi: its
  // weights, booked by where the exit went on a grid four times finer than the table's, have the
  // expectation int f_c(wi, wo) |cos theta_o| dwo over each fine cell, f = rest k(wi) + lobe
  // (fiber_sampler.h), the integral by the midpoint rule on 24 x 24 directions per fine cell. The
  // lobe (about 9 degrees wide) is resolved by the fine cells and would not be by the table's
  // (22 degrees); the weights' total is the table's albedo over wi's bin, in every channel.
  const TabulatedBsdfTable full = table_with_lobe(4);
  std::vector<double> cells;
  const TabulatedBsdfTable rest = full.without_surface_lobe("", 1, &cells);
  const FiberSampler fs(rest, *full.surface_lobe, cells);
  const DirectionGrid fine{16};
  const double t = 50 * kPi / 180;
  Crossings x = one_point(0);
  x.pts[0].wi_local = normalize(Vec3{std::sin(t) * 0.8, std::sin(t) * 0.6, std::cos(t)});
  x.pts[0].bin = fs.grid.bin_of(x.pts[0].wi_local);
  const int n = 400000, bins = fine.bins();
  std::vector<double> sum(static_cast<size_t>(bins) * 3, 0.0), sum2(sum.size(), 0.0);
  Rng rng(31, 0);
  for (int k = 0; k < n; ++k) {
    const Strategies st = draw_strategies(true, fs.groups, rng);
    Particle s = particle_of_weight(1.0, st, false);
    std::vector<double> s_sum(fs.groups);
    albedo_sums(fs, st, x, s_sum);
    const auto draw = draw_scatter(fs, st, x, s_sum, rng);
    if (!draw) continue;  // a lobe draw below the horizon: no light
    weigh_scatter_lobe(fs, rest, st, x.pts[0], *draw, s_sum, s);
    const size_t b = static_cast<size_t>(fine.bin_of(draw->wo_local));
    for (int c = 0; c < 3; ++c) sum[b * 3 + c] += s.w[c], sum2[b * 3 + c] += s.w[c] * s.w[c];
  }
  std::array<double, 3> rho{}, scale{}, total{};
  fs.exact_lobe_split(x.pts[0].bin, x.pts[0].wi_local, rho, scale);
  int checked = 0, beyond = 0;
  for (int b = 0; b < bins; ++b) {
    const int coarse = fs.grid.bin_of(fine.bin_center(b));
    std::array<double, 3> expected{};
    const int m = 24;
    for (int a = 0; a < m * m; ++a) {
      const Vec3 wo =
          DirectionGrid::to_direction(fine.chart_point(b, (a % m + 0.5) / m, (a / m + 0.5) / m));
      std::array<double, 3> lobe{};
      full.surface_lobe->eval(wo, x.pts[0].wi_local, lobe);
      for (int c = 0; c < 3; ++c)
        expected[c] += (rest.at(x.pts[0].bin, coarse, c) * scale[c] + lobe[c]) * std::abs(wo.z);
    }
    for (int c = 0; c < 3; ++c) {
      expected[c] *= fine.bin_solid_angle() / (m * m);
      total[c] += sum[b * 3 + c] / n;
      const double mean = sum[b * 3 + c] / n;
      const double se = std::sqrt(std::max(0.0, sum2[b * 3 + c] / n - mean * mean) / n);
      if (expected[c] < 1e-4) continue;
      ++checked;
      // The midpoint rule's own error near the lobe's peak is about 0.5 %.
      if (std::abs(mean - expected[c]) > 4.5 * se + 0.005 * expected[c]) ++beyond;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_LE(beyond, 2) << "of " << checked;
  for (int c = 0; c < 3; ++c) {
    const double table = fs.albedo_of(x.pts[0].bin, c) + fs.lobe_albedo_of(x.pts[0].bin, c);
    EXPECT_GT(rho[c], 0.02) << c;
    EXPECT_NEAR(total[c], table, 0.01 * table) << c;
  }
}
