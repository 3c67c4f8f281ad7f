// The benchmark library's arithmetic and baselines: the per-cell error and the power-law fit of
// `weft bench bake` against closed forms, and the bare Embree queries of `weft bench render`
// against the renderer's own queries (the baseline must trace the same rays to the same hits).
#include <gtest/gtest.h>

#include <cmath>

#include "weft/bench/bake_bench.h"
#include "weft/bench/fiber_bench.h"
#include "weft/bench/render_bench.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"

using namespace weft;

TEST(BakeBench, CellMomentsGiveTheRelativeRmsError) {
  // Cells (1, 3), (2, 2), (0, 0): means 2, 2, 0; unbiased variances 2, 0, 0; so
  // sqrt(2 / (4 + 4)) = 0.5.
  CellMoments m;
  const std::vector<float> a{1, 2, 0}, b{3, 2, 0};
  m.add(a);
  EXPECT_THROW(m.relative_rms_error(), Error);  // one table has no spread
  m.add(b);
  EXPECT_DOUBLE_EQ(m.relative_rms_error(), 0.5);
  EXPECT_THROW(m.add(std::vector<float>{1, 2}), Error);
  CellMoments dark;
  dark.add(std::vector<float>{0, 0});
  dark.add(std::vector<float>{0, 0});
  EXPECT_EQ(dark.relative_rms_error(), 0.0);
}

TEST(BakeBench, PowerLawFitRecoversExponentAndScale) {
  const std::vector<double> x{10, 100, 1000, 5000},
      y{3 / std::sqrt(10.0), 0.3, 3 / std::sqrt(1000.0), 3 / std::sqrt(5000.0)};
  const auto fit = fit_power_law(x, y);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->b, -0.5, 1e-12);
  EXPECT_NEAR(fit->a, std::log(3.0), 1e-12);
  EXPECT_NEAR(fit->x_at(0.03), 1e4, 1e-6);  // 3 / sqrt(1e4) = 0.03
  // Points of zero error are left out; fewer than two points give no fit.
  EXPECT_FALSE(fit_power_law(std::vector<double>{10, 100}, std::vector<double>{0.1, 0}));
  const auto two =
      fit_power_law(std::vector<double>{10, 100, 1000}, std::vector<double>{1, 0, 0.01});
  ASSERT_TRUE(two);
  EXPECT_NEAR(two->b, -1, 1e-12);
}

TEST(BakeBench, ErrorFallsWithPhotons) {
  BakeBenchOptions o;
  o.photons_per_band = {40, 640};
  o.resolution = 2;
  o.seeds = 3;
  int seen = 0;
  const BakeBenchResult r =
      bench_bake(load_fiber_spec("red-cotton"), o, [&](const BakeBenchRun&) { ++seen; });
  EXPECT_EQ(seen, 2);
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_EQ(r.runs[0].photons_per_band, 40);
  EXPECT_GT(r.runs[0].relative_rms_error, 0);
  // 16 times the photons: about a quarter of the error (Monte Carlo); certainly less than half.
  EXPECT_LT(r.runs[1].relative_rms_error, 0.5 * r.runs[0].relative_rms_error);
  ASSERT_TRUE(r.fitted_exponent && r.photons_per_band_for_target);
  EXPECT_LT(*r.fitted_exponent, 0);
  EXPECT_GT(*r.photons_per_band_for_target, 640);
  o.seeds = 1;
  EXPECT_THROW(bench_bake(load_fiber_spec("red-cotton"), o), Error);
}

TEST(RenderBench, BareEmbreeFindsTheRenderersHits) {
  WeaveParams p;
  p.yarns = 4, p.segments = 32, p.sides = 6;
  const SceneDescription d = weave_bench_scene(p);
  const RenderScene scene(d);
  const Bounds3 b = scene.bounds();
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    Rng rng(3, uint64_t(i));
    const Vec3 o{b.lo.x + (b.hi.x - b.lo.x) * rng.uniform(),
                 b.lo.y + (b.hi.y - b.lo.y) * rng.uniform(),
                 b.lo.z + (b.hi.z - b.lo.z) * rng.uniform()};
    const double z = 1 - 2 * rng.uniform(), phi = 2 * M_PI * rng.uniform(),
                 r = std::sqrt(1 - z * z);
    const Ray ray{o, {r * std::cos(phi), r * std::sin(phi), z}};
    SurfaceHit hit;
    const bool found = scene.intersect(ray, &hit);
    const double t = embree_hit_distance(scene, to_embree(ray, false));
    ASSERT_EQ(found, std::isfinite(t));
    if (!found) continue;
    ++hits;
    ASSERT_EQ(t, hit.t);
    const Ray shorter{o, ray.d, 0.5 * t}, longer{o, ray.d, 2 * t};
    ASSERT_EQ(embree_occluded(scene, to_embree(shorter, true)), scene.occluded(o, ray.d, 0.5 * t));
    ASSERT_TRUE(embree_occluded(scene, to_embree(longer, true)));
  }
  EXPECT_GT(hits, 100);
}

TEST(FiberBench, BothRepresentationsOfTheSameFibersAreMeasured) {
  FiberBenchOptions o;
  o.rays = 2048;
  o.weave.repeats_x = o.weave.repeats_z = 1;
  o.render.width = o.render.height = 16;
  o.render.spp = 1;
  o.accuracy_spp = 8;
  o.geometries = {{FiberGeometry::Type::curves, 8}, {FiberGeometry::Type::tubes, 6}};
  const auto rows = bench_fibers(o);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].geometry, "curves");
  EXPECT_EQ(rows[1].geometry, "tubes:6");
  EXPECT_EQ(rows[0].fibers, rows[1].fibers);
  EXPECT_EQ(rows[0].triangles, 0u);
  EXPECT_EQ(rows[1].curve_segments, 0u);
  EXPECT_EQ(rows[1].triangles, 2 * 6 * rows[0].curve_segments);
  for (const auto& r : rows) {
    EXPECT_GT(r.rays_per_s, 0);
    EXPECT_GT(r.path_rays_per_s, 0);
    EXPECT_GT(r.hit_fraction, 0.1);  // rays leaving a fiber inside a yarn mostly meet another
  }
  // Round curves render the Lambertian fiber's closed form within the renders' noise.
  EXPECT_LT(std::abs(rows[0].one_fiber_total_error), 4 * rows[0].one_fiber_noise);
  EXPECT_LT(rows[0].one_fiber_rms_error, 4 * rows[0].one_fiber_noise);
}

// The ratio to the replay is taken within each repeat: its median lies in its range, which is
// reported, the render without packets is measured too, and a repeat count out of range is
// refused before any work.
TEST(RenderBench, ReportsTheMedianRatioAndItsRangeOverTheRepeats) {
  WeaveParams p;
  p.yarns = 4, p.segments = 16, p.sides = 4;
  const SceneDescription d = weave_bench_scene(p);
  RenderBenchOptions o;
  o.diffuse_rays = 4096;
  o.render.width = o.render.height = 16;
  o.render.spp = 2;
  o.repeats = 3;
  const RenderBenchResult r = bench_render_scene(d, "tiny", o);
  EXPECT_EQ(r.repeats, 3);
  EXPECT_GT(r.ratio_replay_min, 0);
  EXPECT_LE(r.ratio_replay_min, r.ratio_replay);
  EXPECT_LE(r.ratio_replay, r.ratio_replay_max);
  EXPECT_GT(r.path_rays_per_s, 0);
  EXPECT_GT(r.embree_replay_rays_per_s, 0);
  // The same render with the packets off is measured beside it.
  EXPECT_GT(r.path_rays_per_s_one_by_one, 0);
  EXPECT_GT(r.ratio_replay_one_by_one, 0);
  EXPECT_GT(r.packet_gain, 0);
  for (const int bad : {0, -1, kMaxBenchRepeats + 1}) {
    o.repeats = bad;
    EXPECT_THROW(bench_render_scene(d, "tiny", o), Error) << bad;
  }
}
