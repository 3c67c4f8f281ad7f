// Virtual gonioreflectometer. An ideal diffuse reflector of albedo rho has radiance coefficient
// beta = rho at every light and view direction (by the definition of the radiance coefficient:
// the ratio to an ideal white diffuse reflector under the same light and view; Voloboy et al. 2010
// section 4), and the rendered white reference of a flat sample is exactly E cos(theta_i) / pi.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/gonio.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/description.h"
#include "woven_patch.h"

using namespace weft;

namespace {
using weft::testing::kExamples;

SceneDescription plane(const nlohmann::json& reflectance) {
  SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  d.materials["plane"].params["reflectance"] = reflectance;
  return d;
}

GonioSettings settings(double light_zenith, double light_azimuth) {
  GonioSettings g;
  g.sample = "plane";
  g.light_zenith_deg = light_zenith;
  g.light_azimuth_deg = light_azimuth;
  g.irradiance = Rgb(2.5);
  for (int v = -80; v <= 80; v += 10) g.view_zenith_deg.push_back(v);
  g.width = g.height = 16;
  g.spp = 2;
  return g;
}
}  // namespace

TEST(Gonio, LambertPlaneBetaEqualsAlbedoAtEveryView) {
  const SceneDescription d = plane(0.5);
  for (double lz : {0.0, 30.0, 75.0})
    for (double la : {0.0, 135.0}) {
      SCOPED_TRACE(std::to_string(lz) + "/" + std::to_string(la));
      const GonioResult r = run_gonio(d, settings(lz, la));
      ASSERT_FALSE(r.cancelled);
      ASSERT_EQ(r.rows.size(), 17u);
      EXPECT_NEAR(r.l_white.r, 2.5 * std::cos(lz * M_PI / 180) / M_PI, 1e-15);
      for (const auto& row : r.rows) {
        EXPECT_GT(row.footprint_px, 0);
        EXPECT_NEAR(row.beta.r, 0.5, 1e-9);
        EXPECT_NEAR(row.beta.g, 0.5, 1e-9);
        EXPECT_NEAR(row.beta.b, 0.5, 1e-9);
        EXPECT_LT(row.beta_err, 1e-7);  // direct light on a plane is noise-free
        ASSERT_TRUE(row.white);
        EXPECT_NEAR(row.white->r, 1.0, 1e-9);
        // sum = footprint x rho E cos(theta_i) / pi
        EXPECT_NEAR(row.sum.g, row.footprint_px * 0.5 * r.l_white.g, 1e-9 * row.sum.g);
      }
    }
}

TEST(Gonio, ColouredAlbedoOffPlaneViewsAndBackSide) {
  SceneDescription d = plane(nlohmann::json::array({0.2, 0.4, 0.6}));
  GonioSettings g = settings(40, 10);
  g.view_azimuth_deg = 100;  // a view plane other than the plane of incidence
  for (bool back : {false, true}) {
    SCOPED_TRACE(back);
    // The back side: angles measured from -y. Lambert is two-sided, so nothing changes.
    if (back) d.frame.normal = {0, -1, 0};
    const GonioResult r = run_gonio(d, g);
    for (const auto& row : r.rows) {
      EXPECT_NEAR(row.beta.r, 0.2, 1e-9);
      EXPECT_NEAR(row.beta.g, 0.4, 1e-9);
      EXPECT_NEAR(row.beta.b, 0.6, 1e-9);
    }
  }
}

// A spectral sweep (the description's render.spectral) of a plane bound to a spectral diffuser
// (albedo 0.1 below 590 nm, 0.8 from it): light scatters once, so beta is the band reduction of
// the albedo spectrum, exactly (every path carries every band), at every view.
// The white reference reduces the grey spectrum 1 to the reduction's white (the sum of the band
// weights). A coloured irradiance is refused naming it.
TEST(Gonio, SpectralSweepOfASpectralTableIsItsBandReduction) {
  const std::filesystem::path dir = weft::testing::fresh_test_dir();
  auto albedo = [](int b) { return b >= 20 ? 0.8 : 0.1; };
  TabulatedBsdfTable::from_function(
      4, kNumBands,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        for (int b = 0; b < kNumBands; ++b) v[b] = wo.z * wi.z > 0 ? albedo(b) / kPi : 0;
      },
      2, 1)
      .write_exr(dir / "diffuser.exr");
  SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  d.materials["plane"].type = "fiber_table";
  d.materials["plane"].params = {{"file", (dir / "diffuser.exr").string()}};
  d.render = nlohmann::json{{"spectral", true}};
  GonioSettings g = gonio_settings_from(d);
  ASSERT_TRUE(g.spectral);
  const GonioSettings base = settings(30, 0);
  g.sample = base.sample;
  g.light_zenith_deg = base.light_zenith_deg;
  g.irradiance = base.irradiance;
  g.view_zenith_deg = {-50, 0, 40};
  g.width = g.height = 8;
  g.spp = 2;
  const Rgb want = bands_to_linear_srgb(albedo);
  Rgb white;
  for (const Rgb& w : srgb_band_weights_d65()) white += w;
  const GonioResult r = run_gonio(d, g);
  ASSERT_EQ(r.rows.size(), 3u);
  for (const auto& row : r.rows) {
    EXPECT_NEAR(row.beta.r, want.r, 1e-5 * want.r) << row.view_zenith_deg;
    EXPECT_NEAR(row.beta.g, want.g, 1e-5 * want.g) << row.view_zenith_deg;
    EXPECT_NEAR(row.beta.b, want.b, 1e-5 * want.b) << row.view_zenith_deg;
    ASSERT_TRUE(row.white);
    EXPECT_NEAR(row.white->g, white.g, 1e-6);
  }
  g.irradiance = Rgb(2.5, 2.0, 2.0);
  const std::string e = weft::testing::error_of([&] { run_gonio(d, g); });
  EXPECT_NE(e.find("irradiance"), std::string::npos) << e;
  EXPECT_NE(e.find("grey"), std::string::npos) << e;
}

TEST(Gonio, PaperNormalization) {
  const SceneDescription d = plane(0.5);
  GonioSettings g = settings(30, 0);
  g.normalize_to = Rgb(0.8, 0.9, 1.0);
  const GonioResult r = run_gonio(d, g);
  ASSERT_TRUE(r.beta_normal && r.normalization);
  EXPECT_NEAR(r.beta_normal->r, 0.5, 1e-9);
  EXPECT_NEAR(r.normalization->g, 0.9 / 0.5, 1e-9);
  for (const auto& row : r.rows) {
    ASSERT_TRUE(row.beta_norm);
    EXPECT_NEAR(row.beta_norm->r, 0.8, 1e-9);
    EXPECT_NEAR(row.beta_norm->b, 1.0, 1e-9);
  }
  const std::string csv = gonio_csv(r);
  EXPECT_EQ(
      csv.substr(0, csv.find('\n')),
      "view_zenith_deg,view_azimuth_deg,light_zenith_deg,light_azimuth_deg,sum_r,sum_g,sum_b,"
      "footprint_px,"
      "beta_r,beta_g,beta_b,beta_err,beta_err_r,beta_err_g,beta_err_b,white_r,white_g,white_b,"
      "beta_norm_r,beta_norm_g,beta_norm_b");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 18);
}

TEST(Gonio, ViewDirectionSignConvention) {
  const AngleFrame f;  // normal +y, tangent +x
  // Positive zenith: mirror side of a light at azimuth 0, i.e. towards -x.
  const Vec3 mirror = gonio_view_direction(f, 30, 0);
  EXPECT_NEAR(mirror.x, -0.5, 1e-12);
  EXPECT_NEAR(mirror.y, std::cos(M_PI / 6), 1e-12);
  const Vec3 same = gonio_view_direction(f, -30, 0);
  EXPECT_NEAR(same.x, 0.5, 1e-12);
}

TEST(Gonio, WovenPatchErrorsAreCalibrated) {
  // Noisy case: inter-reflections in a woven patch. Two independent seeds must agree within their
  // reported standard errors, and quadrupling spp must halve the error.
  SceneDescription d = weft::testing::woven_patch();
  d.default_material =
      MaterialBinding{"lambert", {{"reflectance", 0.9}}, std::nullopt, std::nullopt, "default"};
  GonioSettings g;
  g.sample = "patch";
  g.light_zenith_deg = 30;
  g.view_zenith_deg = {-45, 0, 45};
  g.width = g.height = 24;
  g.white_check = false;
  g.spp = 8;
  g.seed = 1;
  const GonioResult a = run_gonio(d, g);
  g.seed = 2;
  const GonioResult b = run_gonio(d, g);
  g.spp = 32;
  const GonioResult c = run_gonio(d, g);
  for (size_t i = 0; i < a.rows.size(); ++i) {
    SCOPED_TRACE(i);
    const auto &ra = a.rows[i], &rb = b.rows[i];
    EXPECT_GT(ra.beta_err, 0);
    EXPECT_LT(ra.beta_err, 0.05 * ra.beta.g);
    const double z = (ra.beta.g - rb.beta.g) / std::hypot(ra.beta_err_rgb.g, rb.beta_err_rgb.g);
    EXPECT_LT(std::abs(z), 4.0);
    const double shrink = ra.beta_err / c.rows[i].beta_err;
    EXPECT_GT(shrink, 1.5);
    EXPECT_LT(shrink, 2.7);
    // Inter-reflection can only add light: with albedo 0.9 the patch is not brighter than white
    // paper, yet clearly lit.
    EXPECT_GT(ra.beta.g, 0.2);
    EXPECT_LT(ra.beta.g, 1.2);
  }
}

TEST(Gonio, BadSettingsAndCancellation) {
  const SceneDescription d = plane(0.5);
  GonioSettings g = settings(30, 0);
  g.sample = "nothing";
  EXPECT_THROW(run_gonio(d, g), Error);
  g = settings(90, 0);
  EXPECT_THROW(run_gonio(d, g), Error);
  g = settings(30, 0);
  g.view_zenith_deg = {95};
  EXPECT_THROW(run_gonio(d, g), Error);
  g = settings(30, 0);
  int calls = 0;
  const GonioResult r = run_gonio(d, g, [&](const ProgressUpdate&) { return ++calls < 3; });
  EXPECT_TRUE(r.cancelled);
  EXPECT_LT(r.rows.size(), g.view_zenith_deg.size());
}
