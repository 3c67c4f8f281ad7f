// "-D key=value" overrides of a scene description (docs/scenes.md, "Overrides") and --camera's
// choice of a glTF camera: a key addresses a value by its JSON path, errors name the key and the
// description's file when it addresses nothing or the kind of value is wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;
using weft::testing::error_of;

namespace {

json scene() {
  return json::parse(R"({
    "objects": [{"type": "quad", "name": "floor", "material": "Material.001",
                 "center": [0, 0, 0], "normal": [0, 1, 0]}],
    "materials": {"Material.001": {"type": "lambert", "params": {"reflectance": 0.5}}},
    "lights": [{"type": "parallel", "irradiance": 2, "zenith_deg": 30},
               {"type": "environment", "radiance": [0.1, 0.2, 0.3]}],
    "camera": {"type": "perspective", "position": [0, 1, 2], "look_at": [0, 0, 0]},
    "render": {"spp": 4}
  })");
}

json overridden(std::vector<SceneOverride> o) {
  json j = scene();
  apply_scene_overrides(j, o, "scene.json");
  return j;
}

std::string override_error(const std::string& key, const std::string& value) {
  return error_of([&] { overridden({{key, value}}); });
}

}  // namespace

TEST(Overrides, SetNumbersColoursTextAndListsByTheirJsonPath) {
  const json j = overridden({{"render.spp", "64"},
                             {"materials.Material.001.params.reflectance", "[0.2, 0.3, 0.4]"},
                             {"lights[0].irradiance", "7.5"},
                             {"lights.1.radiance", "1"},
                             {"camera.type", "orthographic"},
                             {"camera.position", "[0, 5, 0]"}});
  EXPECT_EQ(j["render"]["spp"], 64);
  // "Material.001" holds a dot: the longest name that exists is taken.
  EXPECT_EQ(j["materials"]["Material.001"]["params"]["reflectance"], json({0.2, 0.3, 0.4}));
  EXPECT_EQ(j["lights"][0]["irradiance"], 7.5);
  EXPECT_EQ(j["lights"][1]["radiance"], 1);
  EXPECT_EQ(j["camera"]["type"], "orthographic");
  EXPECT_EQ(j["camera"]["position"], json({0, 5, 0}));
  // Nothing else changed.
  json expect = scene();
  expect["render"]["spp"] = 64;
  expect["materials"]["Material.001"]["params"]["reflectance"] = {0.2, 0.3, 0.4};
  expect["lights"][0]["irradiance"] = 7.5;
  expect["lights"][1]["radiance"] = 1;
  expect["camera"]["type"] = "orthographic";
  expect["camera"]["position"] = {0, 5, 0};
  EXPECT_EQ(j, expect);
}

TEST(Overrides, ANewLastKeyIsCheckedByTheParserLikeAKeyInTheFile) {
  // render.seed is absent from the file but a valid key; a top-level section may be made.
  json j = overridden({{"render.seed", "9"}, {"sweep.spp", "2"}});
  EXPECT_EQ(j["render"]["seed"], 9);
  EXPECT_EQ(j["sweep"]["spp"], 2);
  j = overridden({{"materials.Material.001.params.reflectanse", "0.3"}});
  // Material parameters are read when the render scene is built.
  const std::string e =
      error_of([&] { RenderScene scene(parse_scene_description(j, ".", "scene.json")); });
  EXPECT_NE(e.find("scene.json"), std::string::npos) << e;
  EXPECT_NE(e.find("materials.Material.001.params.reflectanse"), std::string::npos) << e;
}

TEST(Overrides, AKeyThatAddressesNothingIsAnErrorNamingItAndTheFile) {
  std::string e = override_error("materials.cloth.params.reflectance", "0.5");
  EXPECT_NE(e.find("scene.json"), std::string::npos) << e;
  EXPECT_NE(e.find("-D materials.cloth.params.reflectance"), std::string::npos) << e;
  EXPECT_NE(e.find("has no 'cloth'"), std::string::npos) << e;
  EXPECT_NE(e.find("Material.001"), std::string::npos) << e;  // what there is
  e = override_error("lights[5].irradiance", "1");
  EXPECT_NE(e.find("'lights' has 2 entries (indices 0 to 1)"), std::string::npos) << e;
  e = override_error("lights.irradiance", "1");
  EXPECT_NE(e.find("is a list"), std::string::npos) << e;
  e = override_error("render.spp.x", "1");
  EXPECT_NE(e.find("'render.spp' is a number, not an object"), std::string::npos) << e;
  for (const std::string bad : {"render..spp", "render.", "lights[x]", "lights[0]x", "lights["})
    EXPECT_NE(override_error(bad, "1").find("-D " + bad), std::string::npos) << bad;
}

TEST(Overrides, AValueOfTheWrongKindIsAnErrorNamingItAndTheFile) {
  std::string e = override_error("render.spp", "many");
  EXPECT_NE(e.find("scene.json: field '-D render.spp'"), std::string::npos) << e;
  EXPECT_NE(e.find("is a number in the description, but 'many' is text"), std::string::npos) << e;
  e = override_error("materials.Material.001.params", "0.5");
  EXPECT_NE(e.find("an object"), std::string::npos) << e;
  e = override_error("camera.position", "true");
  EXPECT_NE(e.find("a list"), std::string::npos) << e;
  // Text stays text, even when it reads as a number.
  EXPECT_EQ(
      overridden({{"materials.Material.001.type", "42"}})["materials"]["Material.001"]["type"],
      "42");
}

TEST(Overrides, ParseKeyEqualsValue) {
  const SceneOverride o = parse_scene_override("materials.a.params.n=1.5=x");
  EXPECT_EQ(o.key, "materials.a.params.n");
  EXPECT_EQ(o.value, "1.5=x");
  EXPECT_NE(error_of([] { parse_scene_override("render.spp"); }).find("key=value"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_scene_override("=3"); }).find("key=value"), std::string::npos);
}

TEST(Overrides, LoadAppliesThemBeforeParsing) {
  const auto dir = weft::testing::fresh_test_dir();
  std::ofstream(dir / "s.json") << scene().dump();
  const SceneDescription d =
      load_scene_description(dir / "s.json", {{"lights[0].irradiance", "[1, 2, 3]"}});
  ASSERT_EQ(d.lights.directional.size(), 1u);
  EXPECT_EQ(d.lights.directional[0].irradiance, Rgb(1, 2, 3));
  const std::string e = error_of([&] {
    load_scene_description(dir / "s.json", {{"lights[0].irradiance", "-1"}});
  });
  EXPECT_NE(e.find("s.json"), std::string::npos) << e;
  EXPECT_NE(e.find("lights[0].irradiance"), std::string::npos) << e;
}

TEST(SelectCamera, ByNameOrIndexAndTheErrorListsThem) {
  SceneDescription d;
  d.source = "scene.json";
  Camera a, b, c;
  a.yfov_rad = 0.1, b.yfov_rad = 0.2, c.yfov_rad = 0.3;
  d.gltf_cameras = {{"Camera", a}, {"", b}, {"close-up", c}};
  EXPECT_EQ(select_camera(d, "close-up").camera.yfov_rad, 0.3);
  EXPECT_EQ(select_camera(d, "1").camera.yfov_rad, 0.2);  // unnamed, by index
  EXPECT_EQ(select_camera(d, "0").name, "Camera");
  std::string e = error_of([&] { select_camera(d, "3"); });
  EXPECT_NE(e.find("scene.json: field '--camera': no camera with index 3"), std::string::npos) << e;
  EXPECT_NE(e.find("0 'Camera', 1 (unnamed), 2 'close-up'"), std::string::npos) << e;
  e = error_of([&] { select_camera(d, "Kamera"); });
  EXPECT_NE(e.find("no camera named 'Kamera'"), std::string::npos) << e;
  d.gltf_cameras.clear();
  EXPECT_NE(error_of([&] { select_camera(d, "0"); }).find("the scene has no glTF cameras"),
            std::string::npos);
}
