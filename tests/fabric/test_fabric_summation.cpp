// Fabric tables by summation (fabric_summation.h): the paper's warp/weft sum and the visible-layer
// extension, against analytic fiber tables whose fabric is known in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "raytrace_test_util.h"
#include "test_util.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"

using namespace weft;

namespace {

// A whole-fiber table that is Lambertian at every point: f = rho / pi for light and view above
// the point, 0 otherwise.
TabulatedBsdfTable lambert_fiber(int resolution, double rho) {
  auto t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        v[0] = v[1] = v[2] = wo.z > 0 && wi.z > 0 ? rho / kPi : 0.0;
      },
      2, 1);
  t.kind = "fiber";
  return t;
}

// A lossless whole-fiber table of a simple kind: every point sends its share of the light the
// fiber receives uniformly into its outer hemisphere, f = 1 / (2 pi) for any light and views above
// the point. Lossless: per unit length the fiber intercepts 2 R |w_i,perp| of the beam, and its
// points return int_B |cos theta_i(B)| d phi R * int f cos_o d w_o = 4 R |w_i,perp| * 1/2.
TabulatedBsdfTable lossless_uniform_fiber(int resolution) {
  return weft::testing::uniform_fiber(resolution, 0.5 * kInvPi);
}

// The visible-layer method at a table resolution, samples per cell and points per circumference.
FabricSummationOptions visible(int resolution, int samples_per_cell, int circumference_samples) {
  FabricSummationOptions o;
  o.method = FabricSummation::kVisible;
  o.resolution = resolution;
  o.samples_per_cell = samples_per_cell;
  o.circumference_samples = circumference_samples;
  return o;
}

}  // namespace

TEST(FabricSummation, PaperSumTransmitsLightFromBelowOnlyAndTheViewReadingShowsIt) {
  // lossless_uniform_fiber sends 1/2 of the light from either side of a point out through it. On
  // top of the cloth, the paper's sum then passes light from below to views above (f = 1 / (2 pi),
  // transmittance 1/2 seen from above), and nothing below the cloth (light from above is never
  // transmitted, the underside is black): not reciprocal. directional_albedo reads light from a
  // direction, directional_albedo_seen_from what a view gathers; `weft bake fabric` reported the
  // first alone (transmittance 0 at normal incidence).
  FabricSummationOptions o;
  o.resolution = 4;
  o.samples_per_cell = 2;
  const auto t = sum_fabric_table(lossless_uniform_fiber(4), o);
  const DirectionGrid g = t.grid();
  for (int k = 0; k < g.bins(); ++k) {
    const auto from = t.directional_albedo(k), seen = t.directional_albedo_seen_from(k);
    const bool up = g.upper(k);
    EXPECT_NEAR(from.reflectance[0], up ? 0.5 : 0.0, 1e-6) << k;
    EXPECT_NEAR(from.transmittance[0], up ? 0.0 : 0.5, 1e-6) << k;
    EXPECT_NEAR(seen.reflectance[0], up ? 0.5 : 0.0, 1e-6) << k;
    EXPECT_NEAR(seen.transmittance[0], up ? 0.5 : 0.0, 1e-6) << k;
  }
}

TEST(FabricSummation, PaperSumOfALambertianFiberIsALambertianFabric) {
  // The paper's formula looks at each fiber on its top, where its frame is the cloth's (up to a
  // turn about the normal): a Lambertian fiber gives a Lambertian fabric, reflecting rho / pi and
  // transmitting nothing.
  const double rho = 0.7;
  FabricSummationOptions o;
  o.resolution = 4;
  o.samples_per_cell = 4;
  const auto fab = sum_fabric_table(lambert_fiber(8, rho), o);
  EXPECT_EQ(fab.kind, "fabric");
  const DirectionGrid g = fab.grid();
  for (int i = 0; i < g.bins(); ++i)
    for (int k = 0; k < g.bins(); ++k) {
      const double expect = g.upper(i) && g.upper(k) ? rho / kPi : 0.0;
      ASSERT_NEAR(fab.at(i, k, 1), expect, 1e-6) << i << " " << k;
    }
}

TEST(FabricSummation, VisibleLayerOfLambertianFibersAtNormalIncidenceAndView) {
  // A closed layer of Lambertian cylinders lit and seen along the normal: a point at angle phi
  // from the top has radiance (rho / pi) E cos phi and all of the upper half is seen, so the
  // layer's mean radiance over its projected width is int (rho/pi) cos^2 / int cos = rho / 4 * E:
  // the fabric BSDF is rho / 4 (not rho / pi: the flanks send their light sideways).
  const double rho = 0.8;
  FabricSummationOptions o;
  o.method = FabricSummation::kVisible;
  o.circumference_samples = 512;
  std::vector<double> v(3);
  fabric_sum(lambert_fiber(16, rho), o, {0, 0, 1}, {0, 0, 1}, v);
  // The table interpolates between bin centres: 2 % at R = 16.
  EXPECT_NEAR(v[0], rho / 4, 0.02 * rho / 4);
}

TEST(FabricSummation, VisibleLayerConservesEnergyAndTransmitsThroughTheUnderside) {
  // With in-plane fibers the layer returns at most what it receives (single scattering, masking
  // only removes light): directional albedo <= 1 for light from above; and the uniform fiber sends
  // light out of the layer's underside, which the paper's sum cannot.
  FabricSummationOptions o = visible(4, 2, 32);
  const auto fab = sum_fabric_table(lossless_uniform_fiber(8), o);
  const DirectionGrid g = fab.grid();
  for (int i = 0; i < g.bins(); ++i) {
    const auto a = fab.directional_albedo(i);
    EXPECT_LE(a.total(0), 1.0 + 1e-3) << "wi bin " << i;
  }
  EXPECT_GT(fab.directional_albedo(g.bin_of({0, 0, 1})).transmittance[0], 0.05);
  FabricSummationOptions paper = o;
  paper.method = FabricSummation::kPaper;
  EXPECT_EQ(sum_fabric_table(lossless_uniform_fiber(8), paper)
                .directional_albedo(g.bin_of({0, 0, 1}))
                .transmittance[0],
            0.0);
}

TEST(FabricSummation, TurningTheFibersTurnsTheTable) {
  // Fibers all along the weft (y) are the warp layer turned by 90 degrees about the normal:
  // f_y(w_o, w_i) = f_x(T w_o, T w_i) with T the turn that takes y to x.
  FabricSummationOptions ox;
  ox.method = FabricSummation::kVisible;
  ox.circumference_samples = 64;
  ox.top = ox.bottom = {{{1, 0, 0}, 1}};
  FabricSummationOptions oy = ox;
  oy.top = oy.bottom = {{{0, 1, 0}, 1}};
  const auto fiber = lossless_uniform_fiber(8);
  auto turn = [](const Vec3& w) { return Vec3{w.y, -w.x, w.z}; };  // y -> x
  std::vector<double> a(3), b(3);
  for (const auto& [wo, wi] :
       {std::pair{normalize(Vec3{0.3, 0.5, 0.8}), normalize(Vec3{-0.6, 0.2, 0.7})},
        std::pair{normalize(Vec3{0.7, -0.1, 0.3}), normalize(Vec3{0.1, 0.8, 0.5})},
        std::pair{normalize(Vec3{0.2, 0.3, -0.9}), normalize(Vec3{0.4, -0.5, 0.6})}}) {
    fabric_sum(fiber, oy, wo, wi, a);
    fabric_sum(fiber, ox, turn(wo), turn(wi), b);
    EXPECT_NEAR(a[0], b[0], 1e-9 * (1 + b[0]));
  }
  // And the two differ: the test can fail.
  fabric_sum(fiber, ox, normalize(Vec3{0.7, 0, 0.7}), normalize(Vec3{0, 0.6, 0.8}), a);
  fabric_sum(fiber, oy, normalize(Vec3{0.7, 0, 0.7}), normalize(Vec3{0, 0.6, 0.8}), b);
  EXPECT_GT(std::abs(a[0] - b[0]), 1e-3 * (a[0] + b[0]));
}

TEST(FabricSummation, BitIdenticalAtOneAndTwoThreads) {
  FabricSummationOptions o = visible(3, 2, 16);
  o.threads = 1;
  const auto a = sum_fabric_table(lossless_uniform_fiber(4), o);
  o.threads = 2;
  const auto b = sum_fabric_table(lossless_uniform_fiber(4), o);
  EXPECT_EQ(a.values, b.values);
}

TEST(FabricSummation, RejectsBadOptionsAndTables) {
  FabricSummationOptions o;
  o.resolution = 0;
  EXPECT_NE(weft::testing::error_of([&] {
              sum_fabric_table(lossless_uniform_fiber(2), o);
            }).find("resolution"),
            std::string::npos);
  o = {};
  o.top = {{{0, 0, 0}, 1}};
  EXPECT_NE(weft::testing::error_of([&] {
              sum_fabric_table(lossless_uniform_fiber(2), o);
            }).find("orientations"),
            std::string::npos);
  auto fabric = lossless_uniform_fiber(2);
  fabric.kind = "fabric";
  EXPECT_NE(weft::testing::error_of([&] { sum_fabric_table(fabric, FabricSummationOptions{}); }),
            "");
}

TEST(FabricSummation, WeaveTurnedBy90DegreesTurnsTheTable) {
  // A plain weave turned by 90 degrees about the normal swaps warp and weft: its visible fiber
  // orientations turn by T(x, y, z) = (-y, x, z) (cloth frame), and the visible-layer sum turns
  // with them, f_B(T wo, T wi) = f_A(wo, wi), exactly (to rounding) for any fiber table: every
  // fiber's frame turns along. The orientations are tilted out of the cloth (z > 0) so that
  // none is stored as its reverse, which would ask the fiber table for a symmetry it need not
  // have. A fiber table without symmetry: it depends on the azimuth about the axis.
  auto fiber = TabulatedBsdfTable::from_function(
      6, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const double s = (0.2 + 0.1 * wo.x + 0.05 * wi.y + 0.04 * wo.y * wi.x) * kInvPi;
        v[0] = s, v[1] = 0.5 * s * (wo.z > 0), v[2] = 0.3 * s;
      },
      2, 1);
  fiber.kind = "fiber";
  auto turn = [](const Vec3& v) { return Vec3{-v.y, v.x, v.z}; };
  FabricSummationOptions a;
  a.method = FabricSummation::kVisible;
  a.top = {{{1, 0, 0.15}, 2}, {{0.1, 1, 0.3}, 1}};
  a.bottom = {{{1, 0.05, 0.2}, 1}, {{0, 1, 0.1}, 1}};
  FabricSummationOptions b = a;
  for (auto* list : {&b.top, &b.bottom})
    for (auto& o : *list) o.tangent = turn(o.tangent);
  std::vector<double> fa(3), fb(3), fs(3);
  double worst = 0, differs = 0;
  for (int i = 0; i < 40; ++i) {
    const double ti = 0.05 + 1.45 * (i % 8) / 8, pi = 0.7 * i, to = 0.1 + 2.9 * (i % 5) / 5,
                 po = 1.3 * i + 0.4;
    const Vec3 wi{std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)};
    const Vec3 wo{std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to)};
    fabric_sum(fiber, a, wo, wi, fa);
    fabric_sum(fiber, b, turn(wo), turn(wi), fb);
    fabric_sum(fiber, b, wo, wi, fs);
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(fa[c] - fb[c]) / std::max(fa[c], 1e-12));
      differs = std::max(differs, std::abs(fa[c] - fs[c]) / std::max(fa[c], 1e-12));
    }
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(differs, 0.01);  // the sample is not symmetric by itself: the turn is needed
}

namespace {

// visible_fiber_tangents for summation-visible: both sides from one scene, the same tangents as
// one side at a time; it stops (nothing) at each kind of poll: the fibers' copies, the scene
// build and the rays.
TEST(FabricSummation, VisibleTangentsOfBothSidesAreTheSidesAndStopWhenAsked) {
  for (const char* detail : {"yarn", "fiber"}) {
    SCOPED_TRACE(detail);
    const WovenSample sample = weft::testing::default_sample(detail);
    std::vector<std::string> stages;
    const auto both = visible_fiber_tangents(sample, [&](const ProgressUpdate& u) {
      if (stages.empty() || stages.back() != u.stage) stages.emplace_back(u.stage);
      return true;
    });
    ASSERT_TRUE(both);
    const auto same = [](const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
      if (a.size() != b.size()) return false;
      for (size_t k = 0; k < a.size(); ++k)
        if (a[k].x != b[k].x || a[k].y != b[k].y || a[k].z != b[k].z) return false;
      return true;
    };
    EXPECT_TRUE(same(both->top, visible_fiber_tangents(sample, true)));
    EXPECT_TRUE(same(both->bottom, visible_fiber_tangents(sample, false)));
    EXPECT_FALSE(both->top.empty());
    for (const std::string& stage : stages) {
      SCOPED_TRACE(stage);
      const auto stopped =
          visible_fiber_tangents(sample, [&](const ProgressUpdate& u) { return u.stage != stage; });
      EXPECT_FALSE(stopped);
    }
    // Each kind of work polls: the copies (fibers only), the build and the rays.
    EXPECT_NE(std::find(stages.begin(), stages.end(), "scene build"), stages.end());
    EXPECT_NE(std::find(stages.begin(), stages.end(), "visible fibers"), stages.end());
    EXPECT_EQ(std::find(stages.begin(), stages.end(), "scene copies") != stages.end(),
              std::string(detail) == "fiber");
  }
}

}  // namespace
