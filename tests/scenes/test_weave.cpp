// The weave generator: counts, determinism, geometric invariants, and the over/under pattern as
// seen by rays through the loaded glTF.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "mesh_checks.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/scenes/description.h"
#include "weft/scenes/gltf.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;

TEST(Weave, TriangleCountAndDeterminism) {
  WeaveParams p;
  p.yarns = 4, p.segments = 16, p.sides = 5;
  const auto meshes = make_weave(p);
  ASSERT_EQ(meshes.size(), 2u);
  EXPECT_EQ(meshes[0].material, "warp");
  EXPECT_EQ(meshes[1].material, "weft");
  for (const auto& m : meshes) {
    EXPECT_EQ(m.triangle_count(), size_t(4 * 16 * 5 * 2));
    EXPECT_EQ(m.vertex_count(), size_t(4 * 17 * 6));
  }
  EXPECT_EQ(weave_to_gltf(p), weave_to_gltf(p));
  EXPECT_EQ(weave_to_glb(p), weave_to_glb(p));
}

TEST(Weave, NormalsOutwardTangentsAlongTheYarn) {
  WeaveParams p;
  p.yarns = 3, p.segments = 24, p.sides = 8;
  const auto meshes = make_weave(p);
  for (int mi = 0; mi < 2; ++mi) {
    const TriangleMesh& m = meshes[mi];
    const Vec3 axis = mi == 0 ? Vec3{1, 0, 0} : Vec3{0, 0, 1};
    weft::testing::expect_consistent_frames(m, [&](size_t, const Vec3& t) {
      // Centre-line slope is at most A pi / S = 0.1 pi / 0.5: the tangent stays near the axis.
      EXPECT_GT(dot(t, axis), std::cos(std::atan(0.1 * M_PI / 0.5)) - 1e-6);
    });
  }
}

TEST(Weave, RoundTripAndOverUnderSeenByRays) {
  WeaveParams p;
  p.yarns = 4, p.segments = 64, p.sides = 12;
  const auto dir = std::filesystem::temp_directory_path() / "weft_test_weave";
  std::filesystem::create_directories(dir);
  write_weave(dir / "patch.gltf", p);
  const GltfContent c = load_gltf(dir / "patch.gltf");
  const auto made = make_weave(p);
  ASSERT_EQ(c.meshes.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(c.meshes[i]->positions, made[i].positions);
    EXPECT_EQ(c.meshes[i]->tangents, made[i].tangents);
    EXPECT_TRUE(c.meshes[i]->has_name("patch"));
  }
  SceneDescription d;
  d.source = "weave";
  d.meshes = c.meshes;
  d.default_material =
      MaterialBinding{"lambert", nlohmann::json::object(), std::nullopt, std::nullopt, ""};
  const RenderScene scene(d);
  // Straight down onto crossing (i, j): the warp (mesh 0) is on top when i + j is even.
  const double S = 0.5e-3, first = -1.5 * S;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect({{first + i * S, 0.01, first + j * S}, {0, -1, 0}}, &hit));
      EXPECT_EQ(hit.shape, (i + j) % 2 == 0 ? 0u : 1u) << i << "," << j;
      // Shading tangent follows the yarn: x for warp, z for weft.
      const Vec3 axis = hit.shape == 0 ? Vec3{1, 0, 0} : Vec3{0, 0, 1};
      EXPECT_GT(std::abs(dot(hit.shading.s, axis)), 0.99);
      // The top of the upper yarn: centre at +A, radius R above it (A = R = 0.1 mm).
      EXPECT_NEAR(hit.p.y, 0.2e-3, 0.2e-3 * (1 - std::cos(M_PI / 12)) + 1e-9);
    }
  std::filesystem::remove_all(dir);
}

TEST(Weave, BadParametersAreErrors) {
  auto error_of = [](const WeaveParams& p) {
    return weft::testing::error_of([&] { make_weave(p); });
  };
  WeaveParams p;
  p.spacing_mm = 0.15;
  EXPECT_NE(error_of(p).find("spacing-mm"), std::string::npos);
  p = {};
  p.yarns = 0;
  EXPECT_NE(error_of(p).find("yarns"), std::string::npos);
  p = {};
  p.pattern = "twill";
  EXPECT_NE(error_of(p).find("unknown pattern"), std::string::npos);
  p = {};
  p.yarn_radius_mm = NAN;
  EXPECT_NE(error_of(p).find("yarn-radius-mm"), std::string::npos);
  EXPECT_THROW(write_weave("patch.obj", WeaveParams{}), Error);
}
