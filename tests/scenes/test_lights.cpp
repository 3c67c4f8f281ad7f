// The Light interface (lights.h): for every kind, sample, pdf and eval agree with each other and
// with closed forms, and each draws the random numbers its header promises.
//  * Delta lights arrive as irradiance L falloff / pdf: E for a parallel beam, I / d^2 (inverse-
//    square law) for a point light, times KHR_lights_punctual's squared linear cone ramp for a
//    spot.
//  * The environment samples the sphere uniformly: E[max(0, w.y) / pdf] is the cosine integral over
//    the upper hemisphere, pi.
//  * The area light: the mean of 1 / pdf over its samples is the solid angle the emitter subtends;
//    for a 2a x 2b rectangle seen on its axis from distance c that is
//    4 asin(a b / sqrt((a^2 + c^2) (b^2 + c^2))) (e.g. Mathar, "Solid angle of a rectangular
//    plate", 2015); and pdf(hit) of a ray that finds the emitter integrates to one over the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;

namespace {

// The number of uniforms 'draw' takes from a stream: the first n for which a fresh stream, after
// n draws, continues like the stream after 'draw'.
template <class Draw>
int draws_of(Draw draw) {
  Rng after(42, 7);
  draw(after);
  const double next = after.uniform();
  for (int n = 0; n < 8; ++n) {
    Rng fresh(42, 7);
    for (int i = 0; i < n; ++i) fresh.uniform();
    if (fresh.uniform() == next) return n;
  }
  return -1;
}

json quad(const std::string& name, const Vec3& c, const Vec3& n, double w, double h) {
  return {{"type", "quad"},
          {"name", name},
          {"material", name},
          {"center", {c.x, c.y, c.z}},
          {"normal", {n.x, n.y, n.z}},
          {"tangent", {1, 0, 0}},
          {"size", {w, h}}};
}

json emitter(double radiance, bool two_sided) {
  return {{"type", "lambert"},
          {"params", {{"reflectance", 0.0}}},
          {"emission", radiance},
          {"double_sided", two_sided}};
}

// A 1 m (x) by 2 m (z) emitter of radiance 2 at height 1, facing down.
SceneDescription lamp_scene() {
  const json j = {{"objects", {quad("lamp", {0, 1, 0}, {0, -1, 0}, 1, 2)}},
                  {"materials", {{"lamp", emitter(2.0, false)}}}};
  return parse_scene_description(j, ".", "lamp.json");
}

const Light& only_light(const RenderScene& scene) {
  EXPECT_EQ(scene.lights().size(), 1u);
  return scene.lights().front();
}

// The samples' mean is 'expected' within four standard errors, and that error is below
// 'max_std_error' (so the check has the power to fail).
void expect_mean(const std::vector<double>& samples, double expected, double max_std_error) {
  const weft::testing::SampleMean e = weft::testing::sample_mean(static_cast<int>(samples.size()),
                                                                 [&](int i) { return samples[i]; });
  EXPECT_LT(e.std_error, max_std_error);
  EXPECT_NEAR(e.mean, expected, 4 * e.std_error);
}

}  // namespace

TEST(LightInterface, ParallelLightArrivesAsIrradianceFromInfinity) {
  const Light light = DirectionalLight{normalize(Vec3{1, 2, 0}), Rgb(1, 2, 3)};
  EXPECT_TRUE(light.is_delta());
  Rng rng(1);
  const auto s = light.sample({5, -3, 2}, rng);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->wi, normalize(Vec3{1, 2, 0}));
  EXPECT_TRUE(s->at_infinity);
  EXPECT_EQ(s->L * (s->falloff / s->pdf), Rgb(1, 2, 3));
  // BSDF sampling never finds a delta light.
  EXPECT_EQ(light.eval(LightHit::escaped_along(s->wi)), Rgb(0.0));
  EXPECT_EQ(light.pdf(LightHit::escaped_along(s->wi)), 0.0);
  EXPECT_EQ(draws_of([&](Rng& r) { light.sample({0, 0, 0}, r); }), 0);
}

TEST(LightInterface, PointAndSpotLightsFollowTheInverseSquareLaw) {
  PointLight point;
  point.position = {0, 2, 0};
  point.intensity = Rgb(3.0);
  const Light light = point;
  Rng rng(1);
  const Vec3 p{1.5, 0, 0};
  const auto s = light.sample(p, rng);
  ASSERT_TRUE(s);
  EXPECT_FALSE(s->at_infinity);
  EXPECT_EQ(s->p_light, point.position);
  EXPECT_NEAR(length(s->wi - normalize(point.position - p)), 0, 1e-15);
  const double d2 = 2 * 2 + 1.5 * 1.5;
  EXPECT_NEAR((s->L * (s->falloff / s->pdf)).g, 3.0 / d2, 1e-15);
  EXPECT_FALSE(light.sample(point.position, rng));  // no direction from the light itself
  EXPECT_EQ(light.pdf(LightHit::escaped_along({0, 1, 0})), 0.0);
  EXPECT_EQ(draws_of([&](Rng& r) { light.sample(p, r); }), 0);

  PointLight spot = point;
  spot.spot_direction = {0, -1, 0};
  spot.cos_inner = std::cos(deg_to_rad(20));
  spot.cos_outer = std::cos(deg_to_rad(30));
  const Light spot_light = spot;
  auto at_angle = [&](double deg) { return Vec3{2 * std::tan(deg_to_rad(deg)), 0, 0}; };
  EXPECT_EQ(spot_light.sample(at_angle(10), rng)->falloff, 1.0);  // inside the inner cone
  EXPECT_FALSE(spot_light.sample(at_angle(40), rng));             // outside the outer cone
  const double ramp =
      (std::cos(deg_to_rad(25)) - spot.cos_outer) / (spot.cos_inner - spot.cos_outer);
  EXPECT_NEAR(spot_light.sample(at_angle(25), rng)->falloff, ramp * ramp, 1e-12);
}

TEST(LightInterface, EnvironmentSampleAgreesWithPdfAndEval) {
  const Light light = EnvironmentLight{Rgb(0.5, 1, 2)};
  EXPECT_FALSE(light.is_delta());
  EXPECT_EQ(draws_of([&](Rng& r) { light.sample({0, 0, 0}, r); }), 2);
  // Only rays that leave the scene meet the environment.
  EXPECT_EQ(light.eval(LightHit::on_surface({0, 1, 0}, 0, 0, {0, -1, 0}, 1)), Rgb(0.0));
  EXPECT_EQ(light.pdf(LightHit::on_surface({0, 1, 0}, 0, 0, {0, -1, 0}, 1)), 0.0);
  const int n = 200000;
  std::vector<double> samples;
  for (int i = 0; i < n; ++i) {
    Rng rng(3, uint64_t(i));
    const auto s = light.sample({1, 2, 3}, rng);
    ASSERT_TRUE(s);
    ASSERT_NEAR(length(s->wi), 1, 1e-12);
    ASSERT_TRUE(s->at_infinity);
    const LightHit hit = LightHit::escaped_along(s->wi);
    ASSERT_EQ(light.pdf(hit), s->pdf);
    ASSERT_EQ(light.eval(hit), s->L);
    samples.push_back(std::max(0.0, s->wi.y) / s->pdf);
  }
  expect_mean(samples, kPi, 0.01 * kPi);
}

TEST(LightInterface, AreaLightSampleAgreesWithPdfEvalAndTheSolidAngle) {
  const RenderScene scene(lamp_scene());
  const Light& light = only_light(scene);
  ASSERT_EQ(scene.surface_light(0), &light);
  EXPECT_FALSE(light.is_delta());
  const Vec3 p{0, 0, 0};
  EXPECT_EQ(draws_of([&](Rng& r) { light.sample(p, r); }), 3);
  const int n = 100000;
  std::vector<double> samples;
  for (int i = 0; i < n; ++i) {
    Rng rng(5, uint64_t(i));
    const auto s = light.sample(p, rng);
    ASSERT_TRUE(s);
    ASSERT_FALSE(s->at_infinity);
    EXPECT_EQ(s->L, Rgb(2.0));
    // The ray towards the sample finds the same point of the emitter, where pdf and eval agree
    // with the sample (float intersection: 1e-5 relative).
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect({p, s->wi}, &hit));
    const double dist = length(s->p_light - p);
    ASSERT_NEAR(hit.t, dist, 1e-5 * dist);
    const LightHit at = LightHit::on_surface(s->wi, hit.shape, hit.prim, hit.ng, hit.t);
    ASSERT_NEAR(light.pdf(at), s->pdf, 1e-5 * s->pdf);
    ASSERT_EQ(light.eval(at), s->L);
    samples.push_back(1 / s->pdf);
  }
  const double a = 0.5, b = 1.0, c = 1.0;
  const double omega = 4 * std::asin(a * b / std::sqrt((a * a + c * c) * (b * b + c * c)));
  expect_mean(samples, omega, 0.01 * omega);
}

TEST(LightInterface, AreaLightPdfIntegratesToOne) {
  // Uniform directions from a point under the emitter: E[pdf(hit) 4 pi] over rays that find it = 1.
  const RenderScene scene(lamp_scene());
  const Light& light = only_light(scene);
  const Light environment = EnvironmentLight{Rgb(1.0)};  // a uniform sphere sampler
  const Vec3 p{0.2, 0.1, -0.3};
  const int n = 400000;
  std::vector<double> samples;
  for (int i = 0; i < n; ++i) {
    Rng rng(9, uint64_t(i));
    const Vec3 dir = environment.sample(p, rng)->wi;
    SurfaceHit hit;
    double v = 0;
    if (scene.intersect({p, dir}, &hit))
      v = light.pdf(LightHit::on_surface(dir, hit.shape, hit.prim, hit.ng, hit.t)) * 4 * kPi;
    samples.push_back(v);
  }
  expect_mean(samples, 1.0, 0.02);
}

TEST(LightInterface, AreaLightPicksTrianglesByPowerAndRespectsSides) {
  // Lamp A: one-sided, area 2, radiance 1 (power 2). Lamp B: two-sided, area 0.5, radiance 3
  // (power 0.5 x 3 x 2 sides = 3). Seen from below, B is picked with probability 3 / 5.
  const json j = {
      {"objects",
       {quad("a", {0, 1, 0}, {0, -1, 0}, 1, 2), quad("b", {0, 0.5, 0}, {0, 1, 0}, 1, 0.5)}},
      {"materials", {{"a", emitter(1.0, false)}, {"b", emitter(3.0, true)}}}};
  const RenderScene scene(parse_scene_description(j, ".", "two.json"));
  const Light& light = only_light(scene);
  ASSERT_EQ(scene.surface_light(0), &light);
  ASSERT_EQ(scene.surface_light(1), &light);
  const int n = 40000;
  int on_b = 0;
  for (int i = 0; i < n; ++i) {
    Rng rng(11, uint64_t(i));
    const auto s = light.sample({0.9, 0, 0}, rng);  // sees A's lit side and B's back
    ASSERT_TRUE(s);
    on_b += std::abs(s->p_light.y - 0.5) < 1e-6;
  }
  const double f = double(on_b) / n, sigma = std::sqrt(0.6 * 0.4 / n);
  EXPECT_NEAR(f, 0.6, 4 * sigma);
  // From above, A shows its unlit back: no sample of A arrives, and a ray that finds A meets no
  // radiance.
  int arrived_on_a = 0;
  for (int i = 0; i < 2000; ++i) {
    Rng rng(12, uint64_t(i));
    const auto s = light.sample({0, 3, 0}, rng);
    arrived_on_a += s && std::abs(s->p_light.y - 1) < 1e-6;
  }
  EXPECT_EQ(arrived_on_a, 0);
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect({{0, 3, 0}, {0, -1, 0}}, &hit));
  ASSERT_EQ(hit.shape, 0u);
  EXPECT_EQ(light.eval(LightHit::on_surface({0, -1, 0}, hit.shape, hit.prim, hit.ng, hit.t)),
            Rgb(0.0));
  EXPECT_EQ(light.eval(LightHit::escaped_along({0, 1, 0})), Rgb(0.0));
}

TEST(LightInterface, SceneListsItsLightsInSummationOrder) {
  const json j = {
      {"objects",
       {quad("floor", {0, 0, 0}, {0, 1, 0}, 4, 4), quad("lamp", {0, 1, 0}, {0, -1, 0}, 1, 1)}},
      {"materials", {{"floor", {{"type", "lambert"}}}, {"lamp", emitter(1.0, false)}}},
      {"lights",
       {{{"type", "environment"}, {"radiance", 0.1}},
        {{"type", "point"}, {"position", {0, 2, 0}}, {"intensity", 1}},
        {{"type", "parallel"}, {"zenith_deg", 30}},
        {{"type", "spot"}, {"position", {0, 2, 0}}, {"direction", {0, -1, 0}}, {"intensity", 1}}}}};
  const SceneDescription d = parse_scene_description(j, ".", "order.json");
  const RenderScene scene(d);
  auto kinds = [](const RenderScene& s) {
    std::vector<size_t> k;
    for (const Light& l : s.lights()) k.push_back(l.variant().index());
    return k;
  };
  // Parallel, point, spot, the emissive surfaces, the environment.
  EXPECT_EQ(kinds(scene), (std::vector<size_t>{0, 1, 1, 3, 2}));
  EXPECT_EQ(scene.surface_light(0), nullptr);  // the floor does not emit
  EXPECT_EQ(scene.surface_light(1), &scene.lights()[3]);
  // Other lights keep the emissive surfaces; a black environment contributes nothing and is left
  // out.
  Lights other;
  other.directional.push_back({{0, 1, 0}, Rgb(1.0)});
  const RenderScene relit = scene.with_lights(other);
  EXPECT_EQ(kinds(relit), (std::vector<size_t>{0, 3}));
  EXPECT_EQ(relit.surface_light(1), &relit.lights()[1]);
}
