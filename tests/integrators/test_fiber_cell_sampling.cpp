// A fiber table read by cell ("interpolation": "cell", as `weft verify`'s fiber-level renders
// read it) is sampled by default with a density that follows the cell pairs' own values
// (tabulated_bsdf.h, fiber_table "sampling"). On the fiber-level poplin lit from behind by a
// parallel light, with a fiber of narrow transmission and reflection lobes:
//  * the path tracer's estimate is the same with either density (two estimators of one
//    transport), and the cell density's noise is lower;
//  * the renders with the cell density are bit-identical at 1 and 2 threads (its distributions
//    are built on first use, by whichever thread asks first).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {

// A clear fiber's table in the fiber's frame (z the outward normal): a narrow forward lobe
// (transmission, wi near -wo), a narrower mirror lobe and a little diffuse light, reddish; at
// R = 8 a lobe spans about one table cell. Its albedo stays below 1 for every view.
fs::path write_clear_fiber_table(const fs::path& file) {
  TabulatedBsdfTable t = TabulatedBsdfTable::from_function(
      8, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Vec3 m{-wo.x, -wo.y, wo.z};
        const double f = 12 * std::exp(-60 * length_squared(wi + wo)) +
                         4 * std::exp(-80 * length_squared(wi - m)) + 0.01;
        v[0] = f, v[1] = 0.5 * f, v[2] = 0.3 * f;
      },
      4, 3);
  t.kind = "fiber";
  t.write_exr(file);
  return file;
}

// The bundled poplin at fiber detail (the sample of `weft verify`), its fibers bound to 'table'
// read by cell and sampled as 'sampling' says, lit from behind at normal incidence by a parallel
// light of irradiance pi, seen by an orthographic camera 30 deg from the normal.
SceneDescription backlit_poplin(const fs::path& table, const std::string& sampling) {
  SceneDescription d =
      fiber_patch_description(red_cotton_weave_options(), "backlit poplin", "patch");
  MaterialBinding b;
  b.type = "fiber_table";
  b.params = {{"file", table.string()}, {"interpolation", "cell"}, {"sampling", sampling}};
  b.field = "materials.warp";
  d.materials["warp"] = d.materials["weft"] = b;
  d.lights.directional.push_back({-d.frame.normal, Rgb(kPi)});
  d.camera = frame_box_orthographic(d.object_bounds("patch"),
                                    d.frame.direction(deg_to_rad(30), kPi), d.frame.normal);
  return d;
}

}  // namespace

TEST(FiberCellSampling, BacklitPoplinHasTheSameMeanAndLessNoiseThanTheInterpolatedDensity) {
  // Camera rays at the same random points of the patch's central part for both densities (each
  // path its own stream): the red radiance of the rays, its mean and standard error. Measured
  // (n = 100 000): interpolated density 0.0496 +- 0.0022, cell density 0.0480 +- 0.0015. The two
  // means must agree within 4 standard errors of their difference, and the cell density's
  // standard error must be below 0.8 times the interpolated one's (measured 0.68).
  const fs::path table = write_clear_fiber_table(weft::testing::fresh_test_dir() / "clear.exr");
  RenderSettings s;  // max_depth 16, Russian roulette from depth 3, as `weft verify` renders
  weft::testing::SampleMean e[2];
  int k = 0;
  for (const char* sampling : {"bilinear", "cell"}) {
    const SceneDescription d = backlit_poplin(table, sampling);
    const RenderScene scene(d);
    const Bounds3 box = d.object_bounds("patch");
    const Vec3 to_viewer = d.frame.direction(deg_to_rad(30), kPi);
    RayCounts rays;
    e[k++] = weft::testing::sample_mean(100000, [&](int i) {
      Rng at(7, uint64_t(i));
      const Vec3 target{box.lo.x + (box.hi.x - box.lo.x) * (0.25 + 0.5 * at.uniform()), 0,
                        box.lo.z + (box.hi.z - box.lo.z) * (0.25 + 0.5 * at.uniform())};
      Rng rng(8 + k, uint64_t(i));
      return trace_path(scene, {target + to_viewer * 1e-2, -to_viewer}, s, rng, rays).r;
    });
    std::printf("backlit poplin, %s density: red %.4f +- %.4f\n", sampling, e[k - 1].mean,
                e[k - 1].std_error);
  }
  ASSERT_GT(e[1].mean, 0);
  EXPECT_LT(e[1].std_error, 0.05 * e[1].mean);  // the comparison is meaningful
  EXPECT_NEAR(e[1].mean, e[0].mean, 4 * std::hypot(e[0].std_error, e[1].std_error));
  EXPECT_LT(e[1].std_error, 0.8 * e[0].std_error);
}

TEST(FiberCellSampling, RendersAreBitIdenticalAtOneAndTwoThreads) {
  const fs::path table = write_clear_fiber_table(weft::testing::fresh_test_dir() / "clear.exr");
  const SceneDescription d = backlit_poplin(table, "cell");
  RenderSettings s;
  s.width = 45;
  s.height = 37;
  s.spp = 3;
  s.seed = 5;
  Image im[2];
  for (int threads : {1, 2}) {
    // A scene of its own each time, so each render builds the cell distributions anew.
    const RenderScene scene(d);
    s.threads = threads;
    im[threads - 1] = render(scene, *d.camera, s).image;
  }
  ASSERT_EQ(im[0].rgb.size(), im[1].rgb.size());
  EXPECT_EQ(0, std::memcmp(im[0].rgb.data(), im[1].rgb.data(), im[0].rgb.size() * 4));
  double sum = 0;
  for (float v : im[0].rgb) sum += v;
  EXPECT_GT(sum, 0);
}
