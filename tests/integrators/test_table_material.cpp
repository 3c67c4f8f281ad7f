// A fiber_table baked from a Lambert BSDF must render like the lambert material: the table
// machinery (file, cache, frame, interpolation, sampling) adds nothing of its own. On a plane
// under parallel light (no noise: direct light only) the radiance coefficient is the albedo
// (Voloboy et al. 2010, section 4: beta of an ideal diffuse reflector of albedo rho is rho).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/fiber/fiber_bake.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/integrators/gonio.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {
using weft::testing::kExamples;

// One file per test: ctest runs tests as parallel processes.
fs::path lambert_table(double rho) {
  const fs::path dir =
      fs::temp_directory_path() /
      (std::string("weft-") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(dir);
  const fs::path file = dir / "lambert.exr";
  const auto table = TabulatedBsdfTable::from_function(
      16, 3,
      [rho](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const double f = wo.z * wi.z > 0 ? rho / kPi : 0.0;  // two-sided, as lambert is
        v[0] = v[1] = v[2] = f;
      },
      4, 1);
  table.write_exr(file);
  return file;
}
}  // namespace

TEST(TableMaterial, LambertTableHasTheAlbedoAsRadianceCoefficient) {
  SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  d.materials["plane"].type = "fiber_table";
  d.materials["plane"].params = {{"file", lambert_table(0.5).string()}};
  GonioSettings g;
  g.sample = "plane";
  g.light_zenith_deg = 30;
  g.irradiance = Rgb(1.0);
  // Views up to 50 degrees: bilinear lookups there stay away from the bins that straddle the
  // horizon, whose cell averages are half-lit by construction (materials/bsdf_table.h).
  for (int v = -50; v <= 50; v += 10) g.view_zenith_deg.push_back(v);
  g.width = g.height = 16;
  g.spp = 2;
  const GonioResult r = run_gonio(d, g);
  ASSERT_EQ(r.rows.size(), 11u);
  for (const auto& row : r.rows) {
    // float storage: 1e-6 relative.
    EXPECT_NEAR(row.beta.r, 0.5, 5e-6) << row.view_zenith_deg;
    EXPECT_NEAR(row.beta.g, 0.5, 5e-6) << row.view_zenith_deg;
  }
}

TEST(TableMaterial, LambertTableRendersTheLambertImage) {
  SceneDescription lam = load_scene_description(kExamples / "lambert-plane.json");
  SceneDescription tab = lam;
  tab.materials["plane"].type = "fiber_table";
  tab.materials["plane"].params = {{"file", lambert_table(0.5).string()}};
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 4;
  s.seed = 3;
  const RenderResult a = render(RenderScene(lam), *lam.camera, s);
  const RenderResult b = render(RenderScene(tab), *tab.camera, s);
  ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
  double sa = 0, sb = 0, max_rel = 0;
  for (size_t i = 0; i < a.image.rgb.size(); ++i) {
    sa += a.image.rgb[i];
    sb += b.image.rgb[i];
    if (a.image.rgb[i] > 0)
      max_rel =
          std::max(max_rel, std::abs(double(a.image.rgb[i]) - b.image.rgb[i]) / a.image.rgb[i]);
  }
  ASSERT_GT(sa, 0);
  EXPECT_NEAR(sb / sa, 1.0, 1e-5);
  EXPECT_LT(max_rel, 1e-4);
}

TEST(TableMaterial, LosslessFiberTableInAFurnaceRendersOneUpToGrazingViews) {
  // A lossless fiber in a uniform environment of radiance 1 returns radiance 1 in every direction
  // (the white furnace): int f(wi, wo) |cos theta_i| dwi = 1 for every view wo above B. Shading a
  // plane with a baked white-cotton table (one band, 550 nm) must render 1 at every view, also
  // near the horizon where octahedral tables once gave 0.85 at 60 deg and 0.54 at 80 deg
  // (docs/fiber-bsdf.md). Tolerance: the table's photon noise per view bin (about 1 %) times 4.
  const FiberSpec spec = load_fiber_spec("white-cotton");
  const FiberBandPhysics ph = fiber_band_physics(spec, compute_medium_band(spec, 16));
  FiberBakeSettings s;
  s.resolution = 6;
  s.photons = 2'000'000;
  s.seed = 7;
  const FiberBandTable band = bake_fiber_band_direct(ph, s, nullptr);
  ASSERT_NEAR(band.absorbed_fraction, 0.0, 1e-15);
  TabulatedBsdfTable table;
  table.resolution = s.resolution;
  table.kind = "fiber";
  for (double f : band.f)
    for (int c = 0; c < 3; ++c) table.values.push_back(static_cast<float>(f));
  const fs::path dir = fs::temp_directory_path() / "weft-furnace-fiber-table";
  fs::create_directories(dir);
  table.write_exr(dir / "white.exr");

  SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  d.materials["plane"].type = "fiber_table";
  d.materials["plane"].params = {{"file", (dir / "white.exr").string()}};
  d.lights = {};
  d.lights.environment = Rgb(1.0);
  const RenderScene scene(d);
  const Bounds3 box = d.object_bounds("plane");
  RenderSettings rs;
  rs.max_depth = 1;
  for (double view_deg : {0.0, 30.0, 60.0, 75.0, 85.0}) {
    const Vec3 to_viewer = d.frame.direction(deg_to_rad(view_deg), deg_to_rad(20));
    const Vec3 target = box.center();
    double sum = 0;
    const int n = 20000;
    RayCounts rays;
    for (int k = 0; k < n; ++k) {
      Rng rng(11, static_cast<uint64_t>(view_deg * 10), static_cast<uint64_t>(k));
      const Ray ray{target + 1e-3 * to_viewer, -to_viewer};
      sum += trace_path(scene, ray, rs, rng, rays).g;
    }
    EXPECT_NEAR(sum / n, 1.0, 0.04) << "view " << view_deg << " deg";
  }
}
