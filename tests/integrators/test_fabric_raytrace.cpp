// The ray-traced fabric estimator (integrators/fabric_raytrace.h): analytic cases, energy, its
// noise estimate, reciprocity and determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "weft/core/math.h"
#include "weft/integrators/fabric_raytrace.h"
#include "weft/materials/table_compare.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

// A fiber table given per point: f(wo, wi) in every channel.
template <class F>
TabulatedBsdfTable fiber_table(int resolution, F f) {
  auto t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) { v[0] = v[1] = v[2] = f(wo, wi); },
      2, 1);
  t.kind = "fiber";
  return t;
}

// A flat sheet (a quad facing +y) filling one repeat of period 1 x 1 mm, 0.1 mm thick slab.
WovenSample flat_sheet() {
  WovenSample s;
  TriangleMesh m;
  m.material = "warp";
  const float h = 0.5e-3f;
  m.positions = {-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h};
  m.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  m.tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  m.indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +y
  s.meshes.push_back(m);
  s.summary.period_x_mm = s.summary.period_z_mm = 1;
  s.summary.y_min_mm = -0.05;
  s.summary.y_max_mm = 0.05;
  s.summary.source = "flat sheet";
  s.summary.detail = "yarn";
  return s;
}

FabricRaytraceOptions options(int resolution, uint64_t particles_per_bin) {
  FabricRaytraceOptions o;
  o.resolution = resolution;
  o.particles_per_bin = particles_per_bin;
  return o;
}

// A lossless-shaped "fiber": every point sends a fraction of the light to its outer hemisphere.
TabulatedBsdfTable uniform_fiber(int resolution, double f) {
  return fiber_table(resolution, [f](const Vec3& wo, const Vec3&) { return wo.z > 0 ? f : 0.0; });
}

// The bundled red-cotton sample at yarn or fiber detail.
WovenSample default_sample(const char* detail = "yarn") {
  WeaveOptions o;
  o.detail = detail;
  return make_woven_sample(overlay(red_cotton_weave_options(), o));
}

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
  FabricRaytraceOptions o = options(2, 2000);
  const auto r = raytrace_fabric_table(default_sample(), fiber, o);
  EXPECT_GT(r.wraps, 0u);
  EXPECT_NEAR(r.exited + r.absorbed + r.lost + r.roulette_net, 1.0, 1e-9);
  EXPECT_LT(r.lost, 0.01);
  // Nothing leaves through the repeat's sides unbooked: the books close above. The only loss is
  // geometric: a line that crosses a tube's surface once (where the lens sections press on each
  // other and at their sharp edges) keeps only that point's half (0.4 % of the power here).
  EXPECT_LT(std::abs(r.absorbed), 0.005);
  EXPECT_NEAR(r.exited, 1.0, 0.01);
}

TEST(FabricRaytrace, NoiseEstimateMatchesTheSpreadOfIndependentRuns) {
  // Two runs with different seeds differ by sqrt(2) x the stated relative noise (weft compare's
  // rel_rms weighting), within 25 %.
  const auto fiber = fiber_table(4, [](const Vec3& wo, const Vec3& wi) {
    return wo.z > 0 ? (0.3 + 0.2 * std::max(0.0, wi.z)) * kInvPi : 0.0;
  });
  FabricRaytraceOptions o = options(3, 4000);
  const auto a = raytrace_fabric_table(default_sample(), fiber, o);
  o.seed = 2;
  const auto b = raytrace_fabric_table(default_sample(), fiber, o);
  const double measured = compare_tables(a.table, b.table).overall.rel_rms;
  const double stated =
      std::sqrt(0.5 * (a.relative_noise * a.relative_noise + b.relative_noise * b.relative_noise)) *
      std::sqrt(2.0);
  EXPECT_NEAR(measured / stated, 1.0, 0.25) << measured << " vs " << stated;
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
  FabricRaytraceOptions o = options(2, 2000);
  const auto r = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_GT(r.wraps, 0u);
  EXPECT_GT(r.scatterings, r.particles);  // light meets several fibers on its way
  EXPECT_NEAR(r.exited + r.absorbed + r.lost + r.roulette_net, 1.0, 1e-9);
  EXPECT_LT(std::abs(r.absorbed), 0.005);
  EXPECT_NEAR(r.exited, 1.0, 0.01);
}

TEST(FabricRaytrace, FiberLevelBitIdenticalAtOneAndTwoThreads) {
  const auto fiber = uniform_fiber(3, 0.4 * kInvPi);
  FabricRaytraceOptions o = options(2, 300);
  o.threads = 1;
  const auto a = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(default_sample("fiber"), fiber, o);
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_EQ(a.exited, b.exited);
  EXPECT_EQ(a.scatterings, b.scatterings);
}
