// Direct lighting against closed forms: a Lambert floor (albedo rho) under
//  * a point light of intensity I at height h: L = rho / pi * I cos(theta) / d^2 (inverse-square
//  law);
//  * a spot light: the same times the KHR_lights_punctual falloff (squared linear ramp in cos
//    between the outer and inner cone angles, KHR_lights_punctual README, "Inner and Outer Cone
//    Angles");
//  * a rectangular area light of radiance Le parallel to the floor: L = rho Le F, with F the
//    configuration factor from a differential area to a parallel rectangle, summed over the four
//    quadrants (J. R. Howell, A Catalog of Radiation Heat Transfer Configuration Factors, factor
//    B-3: F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X =
//    a/c, Y = b/c). The closed form is cross-checked against direct quadrature of cos(theta)
//    cos(theta') / (pi r^2) over the rectangle.
// Next-event estimation alone, BSDF sampling alone and their MIS combination must each agree with
// the closed form, and with each other, within their standard errors. Delta lights add up: the
// image with all of them is the sum of the images with each.
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/integrators/masked_render.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;
using weft::testing::sample_mean;
using weft::testing::SampleMean;

namespace {

constexpr double kRho = 0.8;

// A quad with its first side along x.
json quad(const std::string& name, const std::string& material, const json& center,
          const json& normal, const json& size) {
  return {{"type", "quad"},   {"name", name},         {"material", material}, {"center", center},
          {"normal", normal}, {"tangent", {1, 0, 0}}, {"size", size}};
}

json floor_scene() {
  return {{"objects", {quad("floor", "floor", {0, 0, 0}, {0, 1, 0}, {40, 40})}},
          {"materials", {{"floor", {{"type", "lambert"}, {"params", {{"reflectance", kRho}}}}}}}};
}

// Adds a black emitter of radiance 1 (object and material "lamp").
void add_lamp(json& j, const json& center, const json& normal, const json& size) {
  j["objects"].push_back(quad("lamp", "lamp", center, normal, size));
  j["materials"]["lamp"] = {
      {"type", "lambert"}, {"params", {{"reflectance", 0.0}}}, {"emission", 1.0}};
}

// A camera ray that hits the floor at p from 60 degrees off the normal, starting 1 m away (below
// every light). The hit point is exact to float precision of ~1 m coordinates, hence the 1e-6
// relative tolerance of the noise-free checks.
Ray ray_to(const Vec3& p) {
  const Vec3 dir = normalize(Vec3{-std::sin(M_PI / 3), -std::cos(M_PI / 3), 0});
  return {p - dir * 1.0, dir};
}

double corner_factor(double a, double b, double c) {
  const double X = a / c, Y = b / c;
  const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
  return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2 * M_PI);
}

// Mean channel-average radiance of n paths along one ray, with its standard error.
SampleMean estimate(const RenderScene& scene, const Ray& ray, const RenderSettings& s, int n) {
  RayCounts rays;
  return sample_mean(n, [&](int i) {
    Rng rng(s.seed, uint64_t(i));
    return trace_path(scene, ray, s, rng, rays).average();
  });
}

}  // namespace

TEST(Lights, PointLightInverseSquare) {
  json j = floor_scene();
  j["lights"] = {{{"type", "point"}, {"position", {0, 2, 0}}, {"intensity", 3.0}}};
  const RenderScene scene(parse_scene_description(j, ".", "point.json"));
  RenderSettings s;
  s.max_depth = 1;
  for (double x : {0.0, 1.5}) {
    Rng rng(1);
    RayCounts rays;
    const double L = trace_path(scene, ray_to({x, 0, 0}), s, rng, rays).average();
    const double d2 = 4 + x * x, cos_t = 2 / std::sqrt(d2);
    const double expected = kRho / M_PI * 3.0 * cos_t / d2;
    EXPECT_NEAR(L, expected, 1e-6 * expected);
  }
}

TEST(Lights, SpotLightCones) {
  json j = floor_scene();
  j["lights"] = {{{"type", "spot"},
                  {"position", {0, 2, 0}},
                  {"direction", {0, -1, 0}},
                  {"intensity", 3.0},
                  {"inner_cone_deg", 20},
                  {"outer_cone_deg", 30}}};
  const RenderScene scene(parse_scene_description(j, ".", "spot.json"));
  RenderSettings s;
  s.max_depth = 1;
  auto L_at = [&](double angle_deg) {
    const double x = 2 * std::tan(angle_deg * M_PI / 180);
    Rng rng(1);
    RayCounts rays;
    return trace_path(scene, ray_to({x, 0, 0}), s, rng, rays).average();
  };
  auto point_value = [](double angle_deg) {
    const double c = std::cos(angle_deg * M_PI / 180), d2 = 4 / (c * c);
    return kRho / M_PI * 3.0 * c / d2;
  };
  EXPECT_NEAR(L_at(10), point_value(10),
              1e-6 * point_value(10));  // inside the inner cone: full intensity
  EXPECT_EQ(L_at(40), 0.0);             // outside the outer cone
  const double c25 = std::cos(25 * M_PI / 180), ci = std::cos(20 * M_PI / 180),
               co = std::cos(30 * M_PI / 180);
  const double ramp = (c25 - co) / (ci - co);
  EXPECT_NEAR(L_at(25), point_value(25) * ramp * ramp, 1e-5 * point_value(25) * ramp * ramp);
}

TEST(Lights, RectangleConfigurationFactorMatchesQuadrature) {
  // Independent check of the closed form used below.
  const double a = 0.5, b = 1.0, c = 1.0;
  const int n = 800;
  double F = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) {
      const double x = (i + 0.5) * a / n, y = (k + 0.5) * b / n, r2 = x * x + y * y + c * c;
      F += c * c / (M_PI * r2 * r2) * (a / n) * (b / n);  // cos theta = cos theta' = c / r
    }
  EXPECT_NEAR(F, corner_factor(a, b, c), 1e-6);
}

TEST(Lights, AreaLightEachStrategyAndMisAgreeWithClosedForm) {
  json j = floor_scene();
  // 1 m (x) by 2 m (z) emitter of radiance 1 at height 1, facing down.
  add_lamp(j, {0, 1, 0}, {0, -1, 0}, {1, 2});
  const RenderScene scene(parse_scene_description(j, ".", "area.json"));
  const double expected = kRho * 1.0 * 4 * corner_factor(0.5, 1.0, 1.0);
  const Ray ray = ray_to({0, 0, 0});
  SampleMean e[3];
  const LightSampling modes[3] = {LightSampling::mis, LightSampling::lights_only,
                                  LightSampling::bsdf_only};
  for (int m = 0; m < 3; ++m) {
    SCOPED_TRACE(m);
    RenderSettings s;
    s.max_depth = 1;
    s.sampling = modes[m];
    s.seed = 100 + m;  // independent samples for the pairwise comparison
    e[m] = estimate(scene, ray, s, 60000);
    EXPECT_LT(e[m].std_error, 0.01 * expected);
    EXPECT_NEAR(e[m].mean, expected, 4 * e[m].std_error);
  }
  // Light sampling alone versus BSDF sampling alone: independent estimates, two-sided z-test.
  const double z = (e[1].mean - e[2].mean) /
                   std::sqrt(e[1].std_error * e[1].std_error + e[2].std_error * e[2].std_error);
  EXPECT_LT(std::abs(z), 4.0);
  // MIS should not be noisier than the worse of its two strategies.
  EXPECT_LE(e[0].std_error, std::max(e[1].std_error, e[2].std_error));
}

TEST(Lights, OneSidedEmitterIsDarkFromBehind) {
  json j = floor_scene();
  add_lamp(j, {0, 1, 0}, {0, 1, 0}, {1, 2});  // faces up
  const RenderScene scene(parse_scene_description(j, ".", "back.json"));
  RenderSettings s;
  s.max_depth = 1;
  const SampleMean e = estimate(scene, ray_to({0, 0, 0}), s, 2000);
  EXPECT_EQ(e.mean, 0.0);
}

TEST(Lights, NeeAndBsdfSamplingAgreePerPixel) {
  // Whole-image comparison of the two strategies, including penumbrae from an occluder: per pixel,
  // (m_nee - m_bsdf)^2 / (var_nee + var_bsdf) summed over pixels is chi-square with one degree of
  // freedom per pixel when both are unbiased. Tested with the Wilson-Hilferty normal
  // approximation (Wilson & Hilferty 1931), one-sided at z < 4. The emitter is large so that BSDF
  // sampling hits it often: its samples are then 0 or rho Le, and sample variances are reliable
  // (with a small emitter they are heavy-tailed and underestimated at any affordable spp).
  json j = floor_scene();
  add_lamp(j, {0, 1.0, 0}, {0, -1, 0}, {3, 3});
  j["objects"].push_back(quad("blocker", "floor", {0.2, 0.5, 0}, {0, 1, 0}, {0.6, 0.6}));
  // Under the blocker, looking straight down at the floor.
  j["camera"] = {{"type", "orthographic"}, {"position", {0, 0.3, 0}}, {"look_at", {0, 0, 0}},
                 {"up", {0, 0, -1}},       {"half_width", 1.5},       {"half_height", 1.5}};
  const SceneDescription d = parse_scene_description(j, ".", "chi2.json");
  const RenderScene scene(d);
  RenderSettings s;
  s.width = s.height = 24;
  s.spp = 256;
  s.max_depth = 1;
  const std::vector<uint8_t> floor = d.select_object("floor");  // sample moments of floor hits
  s.sampling = LightSampling::lights_only;
  s.seed = 1;
  const MaskedRender a = render_masked(scene, *d.camera, s, floor);
  s.sampling = LightSampling::bsdf_only;
  s.seed = 2;
  const MaskedRender b = render_masked(scene, *d.camera, s, floor);
  auto moments = [&](const MaskedRender& r, size_t p, double* mean, double* var) {
    // Channel 1 (all channels are equal here); variance of the pixel mean from the sample variance.
    *mean = r.sum[3 * p + 1];
    *var = std::max(0.0, r.sum_sq[3 * p + 1] - *mean * *mean) / (s.spp - 1);
  };
  double chi2 = 0;
  int dof = 0, lit = 0;
  for (size_t p = 0; p < size_t(s.width) * s.height; ++p) {
    ASSERT_EQ(a.coverage[p], 1.0f);  // the floor fills the film (the blocker is below the camera)
    double ma, va, mb, vb;
    moments(a, p, &ma, &va);
    moments(b, p, &mb, &vb);
    if (va + vb == 0) {
      EXPECT_EQ(ma, mb);  // both exactly zero: fully outside the light's reach
      continue;
    }
    chi2 += (ma - mb) * (ma - mb) / (va + vb);
    ++dof;
    lit += ma > 0;
  }
  ASSERT_GT(dof, 300);
  EXPECT_GT(lit, 300);
  const double k = dof, z = (std::cbrt(chi2 / k) - (1 - 2 / (9 * k))) / std::sqrt(2 / (9 * k));
  EXPECT_LT(z, 4.0) << "chi2 " << chi2 << " for " << dof << " pixels";
}

TEST(Lights, DeltaLightsAddUp) {
  // The estimate is linear in the lights: delta lights draw no random numbers, so every camera
  // sample follows the same path with each light alone and with all of them, and the images add
  // up to float rounding. Two bounces and a blocker make shadows and inter-reflection count.
  json j = floor_scene();
  j["objects"].push_back({{"type", "quad"},
                          {"name", "blocker"},
                          {"material", "floor"},
                          {"center", {0.2, 0.5, 0}},
                          {"normal", {0, 1, 0}},
                          {"tangent", {1, 0, 0}},
                          {"size", {0.6, 0.6}}});
  j["camera"] = {{"type", "orthographic"}, {"position", {0, 3, 0}}, {"look_at", {0, 0, 0}},
                 {"up", {0, 0, -1}},       {"half_width", 1.5},     {"half_height", 1.5}};
  const SceneDescription d = parse_scene_description(j, ".", "sum.json");
  const RenderScene geometry(d);
  Lights all;
  all.directional.push_back({normalize(Vec3{0.3, 1, 0.2}), Rgb(1.0, 0.5, 0.25)});
  all.points.push_back({{0.5, 1.5, 0.5}, Rgb(2.0)});
  PointLight spot;
  spot.position = {-0.5, 2, 0};
  spot.intensity = Rgb(0.5, 1, 3);
  spot.spot_direction = {0, -1, 0};
  spot.cos_inner = std::cos(deg_to_rad(20));
  spot.cos_outer = std::cos(deg_to_rad(40));
  all.points.push_back(spot);
  RenderSettings s;
  s.width = s.height = 24;
  s.spp = 2;
  s.max_depth = 2;
  s.seed = 4;
  const RenderResult together = render(geometry.with_lights(all), *d.camera, s);
  std::vector<double> sum(together.image.rgb.size(), 0.0);
  auto add = [&](const Lights& one) {
    const RenderResult r = render(geometry.with_lights(one), *d.camera, s);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += r.image.rgb[i];
  };
  add({{all.directional[0]}, {}, Rgb(0.0), {}});
  add({{}, {all.points[0]}, Rgb(0.0), {}});
  add({{}, {all.points[1]}, Rgb(0.0), {}});
  double total = 0;
  for (size_t i = 0; i < sum.size(); ++i) {
    total += sum[i];
    // Each image is stored as float: a few float roundings of the larger value.
    ASSERT_NEAR(together.image.rgb[i], sum[i], 4e-7 * std::max(sum[i], 1e-30)) << i;
  }
  EXPECT_GT(total, 0);
}
