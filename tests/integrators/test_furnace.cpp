// White-furnace tests of the path tracer. Sampling modes are tested separately so that MIS and each
// of its strategies must reach the same analytic answer.
//  * A convex Lambert sphere of albedo rho inside a constant environment of radiance 1 has
//    radiance rho everywhere (pbrt-v4 src/pbrt/cpu/integrators_test.cpp, "furnace" scenes: albedo 1
//    gives radiance 1).
//  * Inside a closed enclosure whose walls all emit Le and reflect diffusely with albedo rho, the
//    radiance field is uniform and satisfies L = Le + rho L, so L = Le / (1 - rho) (the rendering
//    equation with a constant solution; e.g. Nori's and Mitsuba's emitting-furnace tests).
#include <gtest/gtest.h>

#include <cmath>

#include "furnace_sphere.h"
#include "test_util.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;
using namespace weft::testing;

namespace {

// Mean channel-average radiance over n camera samples spread over the film.
SampleMean estimate(const RenderScene& scene, const Camera& cam, const RenderSettings& s, int n) {
  RayCounts rays;
  return sample_mean(n, [&](int i) {
    Rng rng(s.seed, uint64_t(i), 0);
    const Ray ray = cam.generate_ray(rng.uniform(), rng.uniform(), 1.0);
    return trace_path(scene, ray, s, rng, rays).average();
  });
}

// A faceted unit sphere at the origin; 'inward' turns its normals to the inside.
json unit_sphere(const std::string& name, const std::string& material, int subdivisions,
                 bool inward) {
  return {{"type", "sphere"},    {"name", name},   {"material", material},
          {"center", {0, 0, 0}}, {"radius", 1.0},  {"subdivisions", subdivisions},
          {"inward", inward},    {"smooth", false}};
}

SceneDescription sphere_in_environment(double albedo) {
  const json j = {
      {"objects", {unit_sphere("ball", "white", 3, false)}},
      {"materials", {{"white", {{"type", "lambert"}, {"params", {{"reflectance", albedo}}}}}}},
      {"lights", {{{"type", "environment"}, {"radiance", 1.0}}}}};
  return parse_scene_description(j, ".", "furnace.json");
}

SceneDescription emitting_enclosure(double albedo, double emission) {
  const json j = {
      {"objects", {unit_sphere("room", "wall", 2, true)}},
      {"materials",
       {{"wall",
         {{"type", "lambert"}, {"params", {{"reflectance", albedo}}}, {"emission", emission}}}}}};
  return parse_scene_description(j, ".", "enclosure.json");
}

}  // namespace

TEST(Furnace, SphereInUniformEnvironmentHasRadianceAlbedo) {
  for (double albedo : {1.0, 0.5})
    expect_furnace_sphere_radiance(RenderScene(sphere_in_environment(albedo)), {0, 0, 3}, albedo);
}

TEST(Furnace, EnvironmentSeenDirectlyIsExact) {
  const RenderScene scene(sphere_in_environment(1.0));
  RenderSettings s;
  Rng rng(1);
  RayCounts rays;
  const Rgb L = trace_path(scene, {{0, 0, 5}, {0, 0, 1}}, s, rng, rays);
  EXPECT_EQ(L, Rgb(1.0));
}

TEST(Furnace, EmittingEnclosureReachesLeOverOneMinusAlbedo) {
  const double albedo = 0.5, le = 0.5;  // L = 0.5 / (1 - 0.5) = 1
  const RenderScene scene(emitting_enclosure(albedo, le));
  const Camera cam =
      Camera::look_at(Camera::Type::perspective, {0.1, -0.2, 0.3}, {1, 0, 0}, {0, 1, 0});
  for (LightSampling mode :
       {LightSampling::mis, LightSampling::lights_only, LightSampling::bsdf_only}) {
    SCOPED_TRACE(mode_name(mode));
    RenderSettings s;
    s.max_depth = 200;
    s.sampling = mode;
    s.seed = 3;
    const SampleMean e = estimate(scene, cam, s, 40000);
    EXPECT_LT(e.std_error, 0.01);
    EXPECT_NEAR(e.mean, le / (1 - albedo), 4 * e.std_error);
  }
}

TEST(Furnace, MaxDepthTruncatesTheSeries) {
  // With at most d bounces the enclosure gives the partial sum Le (1 + rho + ... + rho^d).
  const double albedo = 0.5, le = 0.5;
  const RenderScene scene(emitting_enclosure(albedo, le));
  const Camera cam = Camera::look_at(Camera::Type::perspective, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  for (int depth : {0, 1, 3}) {
    SCOPED_TRACE(depth);
    RenderSettings s;
    s.max_depth = depth;
    s.rr_depth = 1000;  // no roulette: the truncation alone is tested
    s.seed = 11;
    const SampleMean e = estimate(scene, cam, s, 20000);
    const double expected = le * (1 - std::pow(albedo, depth + 1)) / (1 - albedo);
    EXPECT_NEAR(e.mean, expected, 4 * e.std_error + 1e-12);
  }
}
