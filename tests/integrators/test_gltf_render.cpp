// Rendering what users bring in glTF:
//  * a Blender-style export (tests/scenes/data/blender_sun.gltf: a sun of 1000 lux, 30 degrees off
//    the vertical, over a plane seen from above) renders with the exposure of its radiometric
//    value: a Lambert plane of albedo rho under irradiance E at incidence theta has radiance
//    rho / pi * E cos(theta), with E = 1000 lux / 683 lm/W (gltf.h);
//  * the shadow terminator of a low-poly sphere with interpolated normals under a parallel light
//    follows the smooth sphere's, not its facets (path_tracer.cpp, Hanika 2021): the radiance of
//    the band just inside the terminator is compared with a finely tessellated sphere's and with
//    the analytic rho * cos(theta) of a unit sphere lit by irradiance pi.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "weft/core/math.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;

namespace {

const std::filesystem::path kData = std::filesystem::path(WEFT_SOURCE_DIR) / "tests/scenes/data";

double mean_value(const Image& img) {
  double sum = 0;
  for (float v : img.rgb) sum += v;
  return sum / img.rgb.size();
}

}  // namespace

TEST(GltfRender, BlenderSunRendersWithSensibleExposure) {
  constexpr double kRho = 0.8;
  const json j = {
      {"gltf", "blender_sun.gltf"},
      {"materials", {{"Material", {{"type", "lambert"}, {"params", {{"reflectance", kRho}}}}}}}};
  const SceneDescription d = parse_scene_description(j, kData, "blender.json");
  ASSERT_TRUE(d.camera);
  ASSERT_EQ(d.lights.directional.size(), 1u);
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 2;
  s.threads = 1;
  const RenderResult r = render(RenderScene(d), *d.camera, s);
  // The camera (2 m up, yfov 0.6 rad) sees only the 2 m plane: every pixel is the plane's
  // radiance, rho / pi * (1000 / 683 W/m^2) * cos(30 deg) = 0.32288 W m^-2 sr^-1.
  const double expected = kRho / kPi * (1000.0 / 683.0) * std::cos(deg_to_rad(30.0));
  const double mean = mean_value(r.image);
  EXPECT_NEAR(mean, expected, 1e-5 * expected);
  // A sensible exposure for a display: within two stops of mid grey (0.18), where the
  // photometric value read as W/m^2 would give 683 times as much (220).
  EXPECT_GT(mean, 0.18 / 4);
  EXPECT_LT(mean, 0.18 * 4);
}

namespace {

// A unit sphere at the origin (icosphere with 'subdivisions', interpolated normals), Lambert
// albedo rho, lit from +x by irradiance pi, seen from +z by an orthographic camera: a point of the
// sphere with normal n has radiance rho * max(0, n.x); the terminator is the image's line x = 0.
Image render_sphere(int subdivisions, double rho, int size) {
  const json j = {
      {"objects",
       {{{"type", "sphere"},
         {"material", "m"},
         {"center", {0, 0, 0}},
         {"radius", 1.0},
         {"subdivisions", subdivisions}}}},
      {"materials", {{"m", {{"type", "lambert"}, {"params", {{"reflectance", rho}}}}}}},
      {"lights", {{{"type", "parallel"}, {"irradiance", kPi}, {"direction", {1, 0, 0}}}}},
      {"camera",
       {{"type", "orthographic"},
        {"position", {0, 0, 5}},
        {"look_at", {0, 0, 0}},
        {"half_width", 1.0},
        {"half_height", 1.0}}}};
  const SceneDescription d = parse_scene_description(j, ".", "sphere.json");
  RenderSettings s;
  s.width = s.height = size;
  s.spp = 16;
  s.max_depth = 1;  // direct light only: the terminator is a direct-lighting effect
  s.threads = 2;
  return render(RenderScene(d), *d.camera, s).image;
}

struct Band {
  double mean = 0;  // mean red radiance of the pixels whose centre sees the unit sphere with
  double cos = 0;   // n.x in (lo, hi), and the mean analytic rho * n.x there
  int pixels = 0;
};

Band band(const Image& img, double rho, double lo, double hi) {
  Band b;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const double fx = 2 * (x + 0.5) / img.width - 1, fy = 1 - 2 * (y + 0.5) / img.height;
      const double r2 = fx * fx + fy * fy;
      // Stay inside the silhouette, where the low-poly and the true sphere both are.
      if (r2 > 0.8 * 0.8 || fx <= lo || fx >= hi) continue;
      b.mean += img.rgb[3 * (size_t(y) * img.width + x)];
      b.cos += rho * fx;
      ++b.pixels;
    }
  b.mean /= b.pixels;
  b.cos /= b.pixels;
  return b;
}

}  // namespace

TEST(GltfRender, LowPolyShadowTerminatorFollowsTheSmoothSphere) {
  constexpr double kRho = 0.5;
  constexpr int kSize = 96;
  const Image coarse = render_sphere(1, kRho, kSize);  // 80 facets, 42 vertex normals
  const Image fine = render_sphere(6, kRho, kSize);    // 81920 facets: the smooth reference
  // The band just inside the terminator, n.x in (0, 0.15), and the fully lit part, n.x > 0.5.
  const Band ref = band(fine, kRho, 0.0, 0.15), low = band(coarse, kRho, 0.0, 0.15);
  const Band ref_lit = band(fine, kRho, 0.5, 1.0), low_lit = band(coarse, kRho, 0.5, 1.0);
  const Band low_dark = band(coarse, kRho, -1.0, -0.15);
  ASSERT_GT(ref.pixels, 100);
  // The fine sphere is the analytic one within its faceting (0.3 % of the radius).
  EXPECT_NEAR(ref.mean, ref.cos, 0.02 * ref.cos);
  EXPECT_NEAR(ref_lit.mean, ref_lit.cos, 0.01 * ref_lit.cos);
  // The coarse sphere's flat facets lie inside the sphere, so a pixel sees a point with another
  // interpolated normal than the true sphere's there: the lit part is brighter by a factor that
  // only the geometry sets (measured 1.048). The terminator band must carry the same factor, not
  // less: without the lift (Veach's rule alone) its facets behind the light go black and the
  // band's factor falls to 0.81 (measured; 1.043 with it).
  const double lit_factor = low_lit.mean / ref_lit.mean, band_factor = low.mean / ref.mean;
  EXPECT_NEAR(lit_factor, 1.0, 0.06);
  EXPECT_NEAR(band_factor, lit_factor, 0.03) << "band " << low.mean << " reference " << ref.mean;
  // Nothing leaks to the far side.
  EXPECT_EQ(low_dark.mean, 0.0);
}
