// Instanced copies of a periodic sample (SceneDescription::mesh_shifts, tiled_woven_description
// with 'instanced'): the meshes are stored once, the shifts are the copies' shifts, and a
// RenderScene traces them like the stored copies: the same hits (point, normal, shading frame,
// distance) on rays through the repeat and its neighbours. Also woven_sample_size: the counts of
// the sample make_woven_sample builds.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "lambert_scene.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

using weft::testing::all_lambert;
using weft::testing::kWifDir;

TEST(MeshShifts, InstancedTilesHoldTheSampleOnceAtTheCopiesShifts) {
  const WovenSample y = make_woven_sample(red_cotton_weave_options());
  const double px = y.summary.period_x_mm * 1e-3, pz = y.summary.period_z_mm * 1e-3;
  const SceneDescription copies = tiled_woven_description(y, 1, 1, "tiled");
  const SceneDescription inst = tiled_woven_description(y, 1, 1, "tiled", true);
  ASSERT_EQ(inst.meshes.size(), y.meshes.size());
  ASSERT_EQ(inst.mesh_shifts.size(), 9u);
  for (int i = -1; i <= 1; ++i)
    for (int k = -1; k <= 1; ++k) {
      const Vec3& s = inst.mesh_shifts[static_cast<size_t>(3 * (i + 1) + (k + 1))];
      EXPECT_EQ(s.x, static_cast<float>(i * px));
      EXPECT_EQ(s.y, 0.0);
      EXPECT_EQ(s.z, static_cast<float>(k * pz));
    }
  EXPECT_TRUE(copies.mesh_shifts.empty());
  // Fiber detail is copied either way (the fibers' ids name their copy).
  WeaveOptions f = red_cotton_weave_options();
  f.detail = "fiber";
  const SceneDescription fc = tiled_woven_description(make_woven_sample(f), 1, 1, "tiled", true);
  EXPECT_EQ(fc.curves.size(), 9u);
  EXPECT_TRUE(fc.mesh_shifts.empty());
}

// Rays from above and below the cloth, in every direction, over the repeat and a margin into
// its neighbours: the instanced scene finds what the stored copies do. The copies' vertices and
// the instanced hit's are the same floats (render_scene.cpp adds the shift as a copy holds it),
// but Embree intersects an instance in its own frame (the ray's origin shifted in float), so a
// neighbour's hit distance may differ in the last float bits: t and p agree to 1e-6 of the
// sample's size (about 1 mm: 1 nm); hits in the centre copy, whose shift is zero, are the same
// bits.
TEST(MeshShifts, InstancedTilesTraceLikeStoredCopies) {
  WeaveOptions o;
  o.wif = (kWifDir / "54235-plain.wif").string();
  const WovenSample y = make_woven_sample(o);
  const RenderScene copies(all_lambert(tiled_woven_description(y, 1, 1, "tiled")));
  const RenderScene inst(all_lambert(tiled_woven_description(y, 1, 1, "tiled", true)));
  EXPECT_EQ(inst.triangle_count(), copies.triangle_count() / 9);
  const double px = y.summary.period_x_mm * 1e-3, pz = y.summary.period_z_mm * 1e-3;
  const double top = y.summary.y_max_mm * 1e-3 + 1e-4, bottom = y.summary.y_min_mm * 1e-3 - 1e-4;
  Rng rng(7);
  int hits = 0, neighbour_hits = 0, same_bits = 0;
  for (int n = 0; n < 4000; ++n) {
    const bool from_above = n % 2 == 0;
    const Vec3 o{(rng.uniform() - 0.5) * 1.6 * px, from_above ? top : bottom,
                 (rng.uniform() - 0.5) * 1.6 * pz};
    const double a = 2 * kPi * rng.uniform(), c = 0.2 + 0.8 * rng.uniform();
    const double s = std::sqrt(1 - c * c);
    const Vec3 d{s * std::cos(a), from_above ? -c : c, s * std::sin(a)};
    SurfaceHit h1, h2;
    const bool b1 = copies.intersect({o, d, 1e300}, &h1), b2 = inst.intersect({o, d, 1e300}, &h2);
    ASSERT_EQ(b1, b2) << "ray " << n;
    if (!b1) continue;
    ++hits;
    EXPECT_NEAR(h1.t, h2.t, 1e-9) << "ray " << n;
    EXPECT_NEAR(length(h1.p - h2.p), 0, 1e-9) << "ray " << n;
    EXPECT_GT(dot(h1.ng, h2.ng), 1 - 1e-6) << "ray " << n;
    EXPECT_GT(dot(h1.shading.n, h2.shading.n), 1 - 1e-6) << "ray " << n;
    // Copy q of mesh m is shape 9 m + q among the stored copies, shape m when instanced.
    EXPECT_EQ(h1.shape / 9, h2.shape) << "ray " << n;
    const bool centre = h1.shape % 9 == 4;
    neighbour_hits += !centre;
    if (centre && h1.t == h2.t && h1.p.x == h2.p.x && h1.p.y == h2.p.y && h1.p.z == h2.p.z)
      ++same_bits;
    if (centre) {
      EXPECT_EQ(h1.prim, h2.prim) << "ray " << n;
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(neighbour_hits, 200);               // the margin reaches the neighbours
  EXPECT_EQ(same_bits, hits - neighbour_hits);  // the centre copy: the same bits
}

TEST(MeshShifts, EmissiveMeshesAreNotShifted) {
  SceneDescription d =
      tiled_woven_description(make_woven_sample(red_cotton_weave_options()), 1, 1, "tiled", true);
  MaterialBinding glow;
  glow.type = "lambert";
  glow.emission = Rgb(1.0);
  d.default_material = glow;
  const std::string e = weft::testing::error_of([&] { RenderScene scene(d); });
  EXPECT_NE(e.find("mesh_shifts"), std::string::npos) << e;
  EXPECT_NE(e.find("emits"), std::string::npos) << e;
}

// woven_sample_size: at yarn detail the triangles and vertices make_woven_sample builds, exactly;
// at fiber detail the fibers exactly and the curve points as the limit estimates them (every
// fiber one curve of crossings x segments + 1 points), and the sections and points the sample will
// hold, without building anything.
TEST(MeshShifts, SampleSizeCountsTheSampleBeforeBuildingIt) {
  for (const char* draft : {"54235-plain.wif", "8452.wif"}) {
    WeaveOptions o;
    o.wif = (kWifDir / draft).string();
    const WovenSampleSize z = woven_sample_size(o);
    EXPECT_EQ(z.detail, "yarn");
    EXPECT_EQ(z.sides, 16);
    EXPECT_EQ(z.segments_per_crossing, 16);
    if (std::string(draft) == "8452.wif") {
      // 84 warps x 100 picks (scenes/data/wif/README.md): 2 x 8400 crossings of yarn, each 16
      // segments of 16 sides, two triangles a facet.
      EXPECT_EQ(z.triangles, 2.0 * 8400 * 16 * 16 * 2);
      continue;  // built below only for the small draft (8.6 M triangles take seconds)
    }
    const WovenSample s = make_woven_sample(o);
    EXPECT_EQ(z.triangles, double(s.summary.triangles)) << draft;
    EXPECT_EQ(z.vertices, double(s.summary.vertices)) << draft;
  }
  WeaveOptions f = red_cotton_weave_options();
  f.detail = "fiber";
  const WovenSampleSize zf = woven_sample_size(f);
  const WovenSample sf = make_woven_sample(f);
  EXPECT_EQ(zf.curves, double(sf.summary.curves));
  EXPECT_EQ(zf.curve_points, double(sf.summary.curve_points));
  EXPECT_EQ(zf.curve_segments, double(sf.summary.curve_segments));
  // The sections the fibers end in, predicted, and the points then made, exactly: the bundled
  // samples and drafts (the poplin keeps perpendicular sections; the others fall back).
  for (const std::string& file :
       {std::string("examples/red-cotton-weave.json"),
        std::string("examples/polyester-satin-weave.json"),
        std::string("examples/polyester-twill-weave.json"),
        std::string("examples/polyester-taffeta-weave.json"),
        std::string("data/wif/54235-plain.wif"), std::string("data/wif/red-white-twill.wif")}) {
    SCOPED_TRACE(file);
    const std::filesystem::path path = std::filesystem::path(WEFT_SOURCE_DIR) / "scenes" / file;
    WeaveOptions o = path.extension() == ".wif" ? WeaveOptions{} : read_weave_options(path);
    if (path.extension() == ".wif") o.wif = path.string();
    o.detail = "fiber";
    const WovenSampleSize z = woven_sample_size(o);
    const WovenSample s = make_woven_sample(o);
    EXPECT_EQ(z.fiber_sections, s.summary.fiber_sections);
    EXPECT_EQ(z.made_curve_points, double(s.summary.curve_points));
    EXPECT_EQ(z.made_curve_segments, double(s.summary.curve_segments));
  }
  // The 84 x 100 draft (not made here: minutes): 7.26 M points at the default packing, 4.0 M made
  // in vertical sections at packing 0.31 (`weft weave --wif scenes/data/wif/8452.wif --detail
  // fiber --json`, 2026-12-05, docs/verify.md).
  WeaveOptions large;
  large.wif = (kWifDir / "8452.wif").string();
  large.detail = "fiber";
  const WovenSampleSize zl = woven_sample_size(large);
  EXPECT_EQ(zl.fiber_sections, "vertical");
  EXPECT_NEAR(zl.curve_points, 7.26e6, 0.01e6);
  EXPECT_NEAR(zl.made_curve_points, 4.0e6, 0.05e6);
  WeaveOptions bad;
  bad.sides = 2;
  EXPECT_NE(weft::testing::error_of([&] { woven_sample_size(bad); }).find("sides"),
            std::string::npos);
}

}  // namespace
