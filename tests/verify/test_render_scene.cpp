// The patch render's scene (verify_render_scene), built in memory: the same scene, to the bit, as
// the description file that says it in JSON, parsed (description.h).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "weft/verify/render_scene.h"

namespace weft {
namespace {

void expect_same_vec(const Vec3& a, const Vec3& b, const char* what) {
  EXPECT_EQ(a.x, b.x) << what;
  EXPECT_EQ(a.y, b.y) << what;
  EXPECT_EQ(a.z, b.z) << what;
}

// The patch as a scene description file writes it: a 1 m quad "cloth" in the x-z plane, a
// parallel light at zenith 0 (or 180), an orthographic camera framing the cloth from 30 deg.
nlohmann::json patch_description(const nlohmann::json& material, bool transmission,
                                 const VerifySettings& s) {
  using nlohmann::json;
  return json{{"objects", json::array({{{"type", "quad"},
                                        {"name", "cloth"},
                                        {"material", "cloth"},
                                        {"center", {0, 0, 0}},
                                        {"normal", {0, 1, 0}},
                                        {"tangent", {1, 0, 0}},
                                        {"size", {1, 1}}}})},
              {"materials", {{"cloth", material}}},
              {"lights", json::array({{{"type", "parallel"},
                                       {"irradiance", kVerifyRenderIrradiance},
                                       {"zenith_deg", transmission ? 180.0 : 0.0},
                                       {"azimuth_deg", 0.0}}})},
              {"camera",
               {{"type", "orthographic"},
                {"frame_object", "cloth"},
                {"zenith_deg", kVerifyRenderViewZenithDeg},
                {"azimuth_deg", 180.0}}},
              {"render",
               {{"width", s.render_size},
                {"height", s.render_size},
                {"spp", s.render_spp},
                {"seed", s.seed}}}};
}

TEST(VerifyRenderScene, InMemoryIsTheParsedDescriptionToTheBit) {
  const nlohmann::json material = {{"type", "fabric_table"}, {"params", {{"file", "f.exr"}}}};
  VerifySettings s = verify_settings(VerifyQuality::kDraft);
  s.seed = 9;
  for (bool transmission : {false, true}) {
    const SceneDescription a = verify_render_scene(material, transmission, s, "folder");
    const SceneDescription b =
        parse_scene_description(patch_description(material, transmission, s), "folder", "x");
    EXPECT_EQ(a.base_dir, b.base_dir);
    ASSERT_EQ(a.meshes.size(), 1u);
    ASSERT_EQ(b.meshes.size(), 1u);
    EXPECT_TRUE(a.curves.empty());
    const TriangleMesh &ma = *a.meshes[0], &mb = *b.meshes[0];
    EXPECT_EQ(ma.material, mb.material);
    EXPECT_EQ(ma.names, mb.names);
    EXPECT_EQ(ma.positions, mb.positions);
    EXPECT_EQ(ma.normals, mb.normals);
    EXPECT_EQ(ma.tangents, mb.tangents);
    EXPECT_EQ(ma.uvs, mb.uvs);
    EXPECT_EQ(ma.indices, mb.indices);
    ASSERT_EQ(a.materials.size(), 1u);
    const MaterialBinding &ba = a.materials.at("cloth"), &bb = b.materials.at("cloth");
    EXPECT_EQ(ba.type, bb.type);
    EXPECT_EQ(ba.params, bb.params);
    EXPECT_EQ(ba.field, bb.field);
    EXPECT_FALSE(ba.emission);
    EXPECT_FALSE(ba.double_sided);
    ASSERT_EQ(a.lights.directional.size(), 1u);
    ASSERT_EQ(b.lights.directional.size(), 1u);
    expect_same_vec(a.lights.directional[0].to_light, b.lights.directional[0].to_light, "light");
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(a.lights.directional[0].irradiance[k], b.lights.directional[0].irradiance[k]);
    EXPECT_TRUE(a.lights.points.empty());
    EXPECT_TRUE(a.lights.environment_maps.empty());
    ASSERT_TRUE(a.camera && b.camera);
    EXPECT_EQ(a.camera->type, b.camera->type);
    expect_same_vec(a.camera->position, b.camera->position, "position");
    expect_same_vec(a.camera->right, b.camera->right, "right");
    expect_same_vec(a.camera->up, b.camera->up, "up");
    expect_same_vec(a.camera->forward, b.camera->forward, "forward");
    EXPECT_EQ(a.camera->half_width, b.camera->half_width);
    EXPECT_EQ(a.camera->half_height, b.camera->half_height);
    EXPECT_EQ(a.render, b.render);
    EXPECT_TRUE(a.warnings.empty());
  }
}

}  // namespace
}  // namespace weft
