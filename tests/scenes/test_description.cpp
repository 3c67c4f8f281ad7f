// Scene description parsing: the bundled example, bindings, inline objects, cameras, and errors
// that name the file and the field (unknown keys, missing files, bad values).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;

namespace {
using weft::testing::kExamples;

json plane_scene() {
  return json::parse(R"({
    "gltf": "lambert-plane.gltf",
    "materials": {"plane": {"type": "lambert", "params": {"reflectance": 0.5}}},
    "lights": [{"type": "parallel", "irradiance": 2, "zenith_deg": 60, "azimuth_deg": 90}],
    "camera": {"type": "orthographic", "frame_object": "plane", "zenith_deg": 0}
  })");
}

std::string parse_error(const json& j) {
  return weft::testing::error_of([&] { parse_scene_description(j, kExamples, "scene.json"); });
}

// Builds the RenderScene too (material parameters are checked by the registry there).
std::string build_error(const json& j) {
  return weft::testing::error_of(
      [&] { RenderScene(parse_scene_description(j, kExamples, "scene.json")); });
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}
}  // namespace

TEST(Description, BundledLambertPlane) {
  const SceneDescription d = load_scene_description(kExamples / "lambert-plane.json");
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_TRUE(d.meshes[0]->has_name("plane"));
  EXPECT_EQ(d.binding_for("plane").type, "lambert");
  EXPECT_EQ(d.binding_for("plane").params.at("reflectance").get<double>(), 0.5);
  ASSERT_EQ(d.lights.directional.size(), 1u);
  // zenith 30 deg, azimuth 0 in the default frame (normal +y, tangent +x).
  const Vec3 l = d.lights.directional[0].to_light;
  EXPECT_NEAR(l.x, std::sin(deg_to_rad(30)), 1e-12);
  EXPECT_NEAR(l.y, std::cos(deg_to_rad(30)), 1e-12);
  EXPECT_NEAR(l.z, 0, 1e-12);
  ASSERT_TRUE(d.camera);
  EXPECT_EQ(d.camera->type, Camera::Type::orthographic);
  // Framing the 1 x 1 plane from straight above: film half extents 0.5.
  EXPECT_NEAR(d.camera->half_width, 0.5, 1e-9);
  EXPECT_NEAR(d.camera->half_height, 0.5, 1e-9);
  // The render and sweep sections are kept as written for the integrators to read.
  ASSERT_TRUE(d.render && d.sweep);
  EXPECT_EQ(d.render->at("spp").get<int>(), 16);
  EXPECT_EQ(d.sweep->at("sample").get<std::string>(), "plane");
  EXPECT_TRUE(d.warnings.empty());
}

TEST(Description, AzimuthTurnsFromTangentTowardsNormalCrossTangent) {
  const SceneDescription d = parse_scene_description(plane_scene(), kExamples, "scene.json");
  // normal (0,1,0) x tangent (1,0,0) = (0,0,-1): azimuth 90 deg points along -z.
  const Vec3 l = d.lights.directional[0].to_light;
  EXPECT_NEAR(l.x, 0, 1e-12);
  EXPECT_NEAR(l.y, 0.5, 1e-12);
  EXPECT_NEAR(l.z, -std::sin(deg_to_rad(60)), 1e-12);
  EXPECT_EQ(d.lights.directional[0].irradiance, Rgb(2.0));
}

TEST(Description, UnknownKeysAreErrors) {
  json j = plane_scene();
  j["lightz"] = json::array();
  std::string e = parse_error(j);
  EXPECT_TRUE(contains(e, "scene.json") && contains(e, "lightz") && contains(e, "unknown key"))
      << e;
  j = plane_scene();
  j["lights"][0]["irradiance_w"] = 1;
  e = parse_error(j);
  EXPECT_TRUE(contains(e, "lights[0].irradiance_w")) << e;
  j = plane_scene();
  j["materials"]["plane"]["parms"] = json::object();
  e = parse_error(j);
  EXPECT_TRUE(contains(e, "materials.plane.parms")) << e;
  j = plane_scene();
  j["objects"] = {{{"type", "quad"},
                   {"material", "plane"},
                   {"center", {0, 0, 0}},
                   {"normal", {0, 1, 0}},
                   {"radius", 1}}};
  e = parse_error(j);
  EXPECT_TRUE(contains(e, "objects[0].radius") && contains(e, "unknown key")) << e;
}

TEST(Description, MissingFilesAreErrors) {
  json j = plane_scene();
  j["gltf"] = "nowhere.gltf";
  const std::string e = parse_error(j);
  EXPECT_TRUE(contains(e, "scene.json") && contains(e, "gltf") && contains(e, "nowhere.gltf")) << e;
  try {
    load_scene_description(kExamples / "no-such-scene.json");
    FAIL() << "no error";
  } catch (const Error& err) {
    EXPECT_TRUE(contains(err.what(), "no-such-scene.json")) << err.what();
  }
  const auto bad = std::filesystem::temp_directory_path() / "weft_bad_scene.json";
  std::ofstream(bad) << "{\"gltf\": ";
  try {
    load_scene_description(bad);
    FAIL() << "no error";
  } catch (const Error& err) {
    EXPECT_TRUE(contains(err.what(), "weft_bad_scene.json") && contains(err.what(), "invalid JSON"))
        << err.what();
  }
  std::filesystem::remove(bad);
}

TEST(Description, UnboundMaterialIsAnErrorUnlessDefaulted) {
  json j = plane_scene();
  j["materials"] = json::object();
  const std::string e = parse_error(j);
  EXPECT_TRUE(contains(e, "no binding for glTF material 'plane'")) << e;
  j["default_material"] = {{"type", "lambert"}, {"params", {{"reflectance", 0.25}}}};
  const SceneDescription d = parse_scene_description(j, kExamples, "scene.json");
  EXPECT_EQ(d.binding_for("plane").params.at("reflectance").get<double>(), 0.25);
}

TEST(Description, BadValuesAreErrorsNamingTheField) {
  json j = plane_scene();
  j["lights"][0]["irradiance"] = -1;
  EXPECT_TRUE(contains(parse_error(j), "lights[0].irradiance"));
  j = plane_scene();
  j["lights"][0]["zenith_deg"] = 200;
  EXPECT_TRUE(contains(parse_error(j), "lights[0].zenith_deg"));
  j = plane_scene();
  j["lights"][0]["irradiance"] = "bright";
  EXPECT_TRUE(contains(parse_error(j), "must be a number"));
  j = plane_scene();
  j["objects"] = {{{"type", "sphere"},
                   {"material", "plane"},
                   {"center", {0, 0, 0}},
                   {"radius", 1},
                   {"subdivisions", 9}}};
  EXPECT_TRUE(contains(parse_error(j), "objects[0].subdivisions"));
  j = plane_scene();
  j["lights"][0]["type"] = "laser";
  EXPECT_TRUE(contains(parse_error(j), "unknown light type 'laser'"));
  j = plane_scene();
  j["camera"]["frame_object"] = "nothing";
  const std::string cam = parse_error(j);
  EXPECT_TRUE(contains(cam, "camera.frame_object") && contains(cam, "known: plane")) << cam;
  // Material parameters are checked by the material registry when the scene is built.
  j = plane_scene();
  j["materials"]["plane"]["params"]["reflectance"] = 1.5;
  const std::string refl = build_error(j);
  EXPECT_TRUE(contains(refl, "scene.json") && contains(refl, "materials.plane.params.reflectance"))
      << refl;
  j = plane_scene();
  j["materials"]["plane"]["type"] = "velvet";
  EXPECT_TRUE(contains(build_error(j), "unknown material 'velvet'"));
}

TEST(Description, InlineObjectsAndExplicitCamera) {
  const json j = json::parse(R"({
    "objects": [
      {"type": "quad", "name": "floor", "material": "m", "center": [0, 0, 0], "normal": [0, 0, 1],
       "tangent": [1, 0, 0], "size": [2, 4]},
      {"type": "sphere", "name": "ball", "material": "m", "center": [0, 0, 3], "radius": 0.5,
       "subdivisions": 2}
    ],
    "materials": {"m": {"type": "lambert", "params": {"reflectance": 0.3}, "emission": [1, 2, 3]}},
    "camera": {"type": "perspective", "position": [0, -5, 1], "look_at": [0, 0, 1], "up": [0, 0, 1],
               "yfov_deg": 30}
  })");
  const SceneDescription d = parse_scene_description(j, ".", "inline.json");
  ASSERT_EQ(d.meshes.size(), 2u);
  const Bounds3 floor = d.object_bounds("floor");
  EXPECT_NEAR(floor.hi.x - floor.lo.x, 2, 1e-6);
  EXPECT_NEAR(floor.hi.y - floor.lo.y, 4, 1e-6);
  const Bounds3 ball = d.object_bounds("ball");
  EXPECT_NEAR(ball.hi.z, 3.5, 1e-6);
  EXPECT_NEAR(ball.lo.z, 2.5, 1e-6);
  ASSERT_TRUE(d.camera);
  EXPECT_NEAR(d.camera->forward.y, 1, 1e-12);
  EXPECT_NEAR(d.camera->yfov_rad, deg_to_rad(30), 1e-12);
  EXPECT_EQ(*d.materials.at("m").emission, Rgb(1, 2, 3));
  // Sphere triangles face outwards.
  const TriangleMesh& s = *d.meshes[1];
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const Vec3 p0 = s.position(s.indices[3 * t]), p1 = s.position(s.indices[3 * t + 1]),
               p2 = s.position(s.indices[3 * t + 2]);
    EXPECT_GT(dot(cross(p1 - p0, p2 - p0), (p0 + p1 + p2) / 3 - Vec3{0, 0, 3}), 0);
  }
}
