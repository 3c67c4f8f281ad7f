// The integrators read their own settings from a scene description: "render" for the path tracer,
// "sweep" (and the path tracer's part of "render") for the gonioreflectometer. Absent keys take
// the one set of defaults (RenderSettings{}, GonioSettings{}); unknown keys and bad values are
// errors naming the file and the key's JSON path.
#include <gtest/gtest.h>

#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/integrators/gonio.h"
#include "weft/integrators/render_settings.h"

using namespace weft;
using nlohmann::json;

namespace {

using weft::testing::kExamples;

json quad_scene() {
  return {{"objects",
           {{{"type", "quad"},
             {"name", "floor"},
             {"material", "m"},
             {"center", {0, 0, 0}},
             {"normal", {0, 1, 0}}}}},
          {"materials", {{"m", {{"type", "lambert"}}}}}};
}

SceneDescription with(const std::string& section, const json& value) {
  json j = quad_scene();
  j[section] = value;
  return parse_scene_description(j, ".", "scene.json");
}

using weft::testing::error_of;

std::string render_error(const json& render) {
  return error_of([&] { render_settings_from(with("render", render)); });
}
std::string sweep_error(const json& sweep) {
  return error_of([&] { gonio_settings_from(with("sweep", sweep)); });
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// The settings a "render" section sets, compared one by one so that a failure names the key.
void expect_render_keys(const RenderSettings& r, const RenderSettings& want) {
  EXPECT_EQ(r.width, want.width);
  EXPECT_EQ(r.height, want.height);
  EXPECT_EQ(r.spp, want.spp);
  EXPECT_EQ(r.max_depth, want.max_depth);
  EXPECT_EQ(r.rr_depth, want.rr_depth);
  EXPECT_EQ(r.seed, want.seed);
}

}  // namespace

TEST(Settings, AbsentSectionsGiveTheDefaults) {
  const SceneDescription d = parse_scene_description(quad_scene(), ".", "scene.json");
  const RenderSettings def;
  expect_render_keys(render_settings_from(d), def);
  const GonioSettings g = gonio_settings_from(d), gdef;
  EXPECT_EQ(g.sample, gdef.sample);
  EXPECT_EQ(g.width, gdef.width);
  EXPECT_EQ(g.spp, gdef.spp);
  EXPECT_TRUE(g.view_zenith_deg.empty());
  EXPECT_EQ(g.white_check, gdef.white_check);
  // The sweep's path-tracer settings are the renderer's.
  EXPECT_EQ(gdef.max_depth, def.max_depth);
  EXPECT_EQ(gdef.rr_depth, def.rr_depth);
  EXPECT_EQ(gdef.seed, def.seed);
  EXPECT_EQ(g.seed, def.seed);
}

TEST(Settings, BundledExampleSections) {
  const SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  // rr_depth is not given: the default.
  expect_render_keys(
      render_settings_from(d),
      {.width = 128, .height = 128, .spp = 16, .max_depth = 8, .seed = 1, .crop = {}});
  const GonioSettings g = gonio_settings_from(d);
  EXPECT_EQ(g.sample, "plane");
  EXPECT_EQ(g.light_zenith_deg, 30);
  ASSERT_EQ(g.view_zenith_deg.size(), 15u);
  EXPECT_DOUBLE_EQ(g.view_zenith_deg.front(), -70);
  EXPECT_DOUBLE_EQ(g.view_zenith_deg.back(), 70);
  EXPECT_FALSE(g.view_azimuth_deg);
  EXPECT_EQ(g.width, 32);
  EXPECT_EQ(g.height, 32);
  EXPECT_EQ(g.spp, 4);
  // From "render": the sweep traces paths like the render does.
  EXPECT_EQ(g.max_depth, 8);
  EXPECT_EQ(g.seed, 1u);
}

TEST(Settings, EveryRenderKey) {
  const RenderSettings r =
      render_settings_from(with("render", {{"width", 7},
                                           {"height", 5},
                                           {"spp", 3},
                                           {"max_depth", 2},
                                           {"rr_depth", 1},
                                           {"seed", 18446744073709551615ull}}));
  expect_render_keys(r, {.width = 7,
                         .height = 5,
                         .spp = 3,
                         .max_depth = 2,
                         .rr_depth = 1,
                         .seed = 18446744073709551615ull,
                         .crop = {}});
}

TEST(Settings, EverySweepKey) {
  const GonioSettings g = gonio_settings_from(
      with("sweep", {{"sample", "floor"},
                     {"light_zenith_deg", 40},
                     {"light_azimuth_deg", -20},
                     {"irradiance", {1, 2, 3}},
                     {"view_zenith_deg", {{"from", -30}, {"to", 30}, {"step", 15}}},
                     {"view_azimuth_deg", 90},
                     {"normalize_to", 0.5},
                     {"white_check", false},
                     {"width", 8},
                     {"height", 6},
                     {"spp", 2}}));
  EXPECT_EQ(g.sample, "floor");
  EXPECT_EQ(g.light_zenith_deg, 40);
  EXPECT_EQ(g.light_azimuth_deg, -20);
  EXPECT_EQ(g.irradiance, Rgb(1, 2, 3));
  EXPECT_EQ(g.view_zenith_deg, (std::vector<double>{-30, -15, 0, 15, 30}));
  EXPECT_EQ(g.view_azimuth_deg, 90);
  EXPECT_EQ(g.normalize_to, Rgb(0.5));
  EXPECT_FALSE(g.white_check);
  EXPECT_EQ(g.width, 8);
  EXPECT_EQ(g.height, 6);
  EXPECT_EQ(g.spp, 2);
  const GonioSettings list = gonio_settings_from(with("sweep", {{"view_zenith_deg", {-10, 20}}}));
  EXPECT_EQ(list.view_zenith_deg, (std::vector<double>{-10, 20}));
}

TEST(Settings, UnknownKeysAreNamedWithTheirPath) {
  std::string e = render_error({{"sppp", 4}});
  EXPECT_TRUE(contains(e, "scene.json") && contains(e, "render.sppp") && contains(e, "unknown key"))
      << e;
  e = sweep_error({{"view_zenit_deg", {0}}});
  EXPECT_TRUE(contains(e, "scene.json") && contains(e, "sweep.view_zenit_deg") &&
              contains(e, "unknown key"))
      << e;
  e = sweep_error({{"view_zenith_deg", {{"from", 0}, {"to", 10}, {"step", 5}, {"stp", 5}}}});
  EXPECT_TRUE(contains(e, "sweep.view_zenith_deg.stp")) << e;
  // A sweep reads the path tracer's settings too, so a bad "render" fails it.
  json j = quad_scene();
  j["render"] = {{"max_dept", 3}};
  j["sweep"] = json::object();
  const SceneDescription d = parse_scene_description(j, ".", "scene.json");
  e = error_of([&] { gonio_settings_from(d); });
  EXPECT_TRUE(contains(e, "render.max_dept")) << e;
}

TEST(Settings, BadValuesAreNamedWithTheirPath) {
  EXPECT_TRUE(contains(render_error({{"spp", 0}}), "render.spp"));
  EXPECT_TRUE(contains(render_error({{"seed", -1}}), "render.seed"));
  EXPECT_TRUE(contains(render_error({{"width", "wide"}}), "render.width"));
  const std::string not_object = render_error(3);
  EXPECT_TRUE(contains(not_object, "render") && contains(not_object, "JSON object")) << not_object;
  EXPECT_TRUE(contains(sweep_error({{"light_zenith_deg", 95}}), "sweep.light_zenith_deg"));
  EXPECT_TRUE(contains(sweep_error({{"view_zenith_deg", {0, 100}}}), "sweep.view_zenith_deg[1]"));
  EXPECT_TRUE(contains(sweep_error({{"view_zenith_deg", {{"from", 10}, {"to", 0}, {"step", 5}}}}),
                       "needs from <= to"));
  EXPECT_TRUE(contains(sweep_error({{"irradiance", 0}}), "sweep.irradiance"));
  EXPECT_TRUE(contains(sweep_error({{"spp", 1.5}}), "sweep.spp"));
}
