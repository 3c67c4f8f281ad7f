// glTF loading: node transforms (TRS hierarchy and matrices), tangents present / derived from UVs /
// from an arbitrary frame, cameras, KHR_lights_punctual, emissive materials, and malformed files.
// The expected values follow from the construction in data/make_data.py.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/scenes/gltf.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {
const std::filesystem::path kData = std::filesystem::path(WEFT_SOURCE_DIR) / "tests/scenes/data";

Vec3 attr3(const std::vector<float>& a, size_t v, int stride) {
  return {a[stride * v], a[stride * v + 1], a[stride * v + 2]};
}

const TriangleMesh& mesh_named(const GltfContent& c, const std::string& name) {
  for (const auto& m : c.meshes)
    if (m->has_name(name)) return *m;
  throw std::runtime_error("no mesh " + name);
}

void expect_near(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// Error message of loading 'file', or "" when it loads.
std::string load_error(const std::string& file) {
  return weft::testing::error_of([&] { load_gltf(kData / file); });
}
}  // namespace

TEST(Gltf, NodeHierarchyTransformsCube) {
  const GltfContent c = load_gltf(kData / "cube_tangents.gltf");
  const TriangleMesh& cube = mesh_named(c, "child");
  EXPECT_EQ(cube.vertex_count(), 24u);
  EXPECT_EQ(cube.triangle_count(), 12u);
  // Names: own node first, then ancestors, then the glTF mesh name.
  ASSERT_EQ(cube.names.size(), 3u);
  EXPECT_EQ(cube.names[0], "child");
  EXPECT_EQ(cube.names[1], "root");
  EXPECT_EQ(cube.names[2], "cube_mesh");
  EXPECT_EQ(cube.material, "cube_mat");
  // Unit cube scaled by 2, rotated about y, translated by (10, 0, 0).
  const Bounds3 b = cube.bounds();
  expect_near(b.lo, {9, -1, -1}, 1e-6);
  expect_near(b.hi, {11, 1, 1}, 1e-6);
  // Rotation by +90 deg about y maps +x to -z: the +x face's normal becomes -z and its tangent
  // (local -z) becomes -x.
  int found = 0;
  for (size_t v = 0; v < cube.vertex_count(); ++v) {
    const Vec3 n = attr3(cube.normals, v, 3);
    if (std::abs(n.z + 1) < 1e-6 && cube.position(v).z < -0.99) {
      expect_near(attr3(cube.tangents, v, 4), {-1, 0, 0}, 1e-6);
      ++found;
    }
  }
  EXPECT_EQ(found, 4);
}

TEST(Gltf, WindingAgreesWithNormalsAndTangentsAreOrthonormal) {
  for (const char* file : {"cube_tangents.gltf", "cube_no_tangents.gltf", "quad_no_uv.gltf"}) {
    SCOPED_TRACE(file);
    const GltfContent c = load_gltf(kData / file);
    for (const auto& m : c.meshes) {
      ASSERT_EQ(m->tangents.size(), 4 * m->vertex_count());
      for (size_t t = 0; t < m->triangle_count(); ++t) {
        const Vec3 p0 = m->position(m->indices[3 * t]);
        const Vec3 ng = normalize(cross(m->position(m->indices[3 * t + 1]) - p0,
                                        m->position(m->indices[3 * t + 2]) - p0));
        for (int k = 0; k < 3; ++k)
          EXPECT_GT(dot(ng, attr3(m->normals, m->indices[3 * t + k], 3)), 0.999);
      }
      for (size_t v = 0; v < m->vertex_count(); ++v) {
        const Vec3 tn = attr3(m->tangents, v, 4);
        EXPECT_NEAR(length(tn), 1.0, 1e-6);
        EXPECT_NEAR(dot(tn, attr3(m->normals, v, 3)), 0.0, 1e-6);
      }
    }
  }
}

TEST(Gltf, TangentsDerivedFromUvsMatchAuthoredOnes) {
  // The authored tangents of cube_tangents.gltf are exactly dP/du of each face.
  const GltfContent with = load_gltf(kData / "cube_tangents.gltf");
  const GltfContent without = load_gltf(kData / "cube_no_tangents.gltf");
  const TriangleMesh& a = mesh_named(with, "child");
  const TriangleMesh& b = mesh_named(without, "child");
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  for (size_t v = 0; v < a.vertex_count(); ++v)
    expect_near(attr3(b.tangents, v, 4), attr3(a.tangents, v, 4), 1e-6);
}

TEST(Gltf, MatrixWithMirrorAndNoUvs) {
  const GltfContent c = load_gltf(kData / "quad_no_uv.gltf");
  ASSERT_EQ(c.meshes.size(), 1u);
  const TriangleMesh& q = *c.meshes[0];
  EXPECT_TRUE(q.uvs.empty());
  // Column-major matrix: x -> -x, then translate (1, 2, 3). Vertex 0 was (-0.5, 0, 0.5).
  expect_near(q.position(0), {1.5, 2, 3.5}, 1e-6);
  expect_near(attr3(q.normals, 0, 3), {0, 1, 0}, 1e-6);
}

TEST(Gltf, CameraLightsAndEmission) {
  const GltfContent c = load_gltf(kData / "cube_tangents.gltf");
  ASSERT_EQ(c.cameras.size(), 1u);
  const Camera& cam = c.cameras[0].camera;
  EXPECT_EQ(c.cameras[0].name, "ortho_cam");
  EXPECT_EQ(cam.type, Camera::Type::orthographic);
  expect_near(cam.position, {10, 0, 5}, 1e-9);
  expect_near(cam.forward, {0, 0, -1}, 1e-9);
  expect_near(cam.up, {0, 1, 0}, 1e-9);
  EXPECT_DOUBLE_EQ(cam.half_width, 1.5);
  EXPECT_DOUBLE_EQ(cam.half_height, 1.0);
  // The directional light is rotated -90 deg about x: it shines down, so the light is up.
  ASSERT_EQ(c.lights.directional.size(), 1u);
  expect_near(c.lights.directional[0].to_light, {0, 1, 0}, 1e-9);
  EXPECT_EQ(c.lights.directional[0].irradiance, Rgb(3.0));
  ASSERT_EQ(c.lights.points.size(), 1u);
  expect_near(c.lights.points[0].position, {10, 3, 0}, 1e-9);
  EXPECT_EQ(c.lights.points[0].intensity, Rgb(2.0, 1.0, 1.0));
  EXPECT_FALSE(c.lights.points[0].is_spot());
  // emissiveFactor (1, 0.5, 0.25) x emissiveStrength 4.
  ASSERT_TRUE(c.materials.count("glow"));
  EXPECT_EQ(c.materials.at("glow").emission, Rgb(4.0, 2.0, 1.0));
  EXPECT_TRUE(c.materials.at("glow").double_sided);
  EXPECT_EQ(mesh_named(c, "lamp").material, "glow");
  EXPECT_TRUE(c.materials.at("cube_mat").emission.is_black());
}

TEST(Gltf, ExternalBufferAndGlb) {
  const GltfContent c = load_gltf(kData / "quad_external.gltf");
  ASSERT_EQ(c.meshes.size(), 1u);
  EXPECT_EQ(c.meshes[0]->triangle_count(), 2u);
  // The same weave as .gltf (embedded base64) and .glb gives the same meshes.
  WeaveParams p;
  p.yarns = 2, p.segments = 8, p.sides = 4;
  const auto dir = std::filesystem::temp_directory_path() / "weft_test_gltf";
  std::filesystem::create_directories(dir);
  write_weave(dir / "w.gltf", p);
  write_weave(dir / "w.glb", p);
  const GltfContent a = load_gltf(dir / "w.gltf"), b = load_gltf(dir / "w.glb");
  ASSERT_EQ(a.meshes.size(), 2u);
  ASSERT_EQ(b.meshes.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(a.meshes[i]->positions, b.meshes[i]->positions);
    EXPECT_EQ(a.meshes[i]->indices, b.meshes[i]->indices);
  }
  std::filesystem::remove_all(dir);
}

TEST(Gltf, MalformedFilesAreErrorsNamingTheFile) {
  const std::string truncated = load_error("truncated.gltf");
  EXPECT_NE(truncated.find("truncated.gltf"), std::string::npos) << truncated;
  const std::string missing = load_error("missing_buffer.gltf");
  EXPECT_NE(missing.find("missing_buffer.gltf"), std::string::npos) << missing;
  const std::string accessor = load_error("bad_accessor.gltf");
  EXPECT_NE(accessor.find("bad_accessor.gltf"), std::string::npos) << accessor;
  EXPECT_NE(accessor.find("POSITION"), std::string::npos) << accessor;
  EXPECT_NE(accessor.find("out of range"), std::string::npos) << accessor;
  const std::string index = load_error("bad_index.gltf");
  EXPECT_NE(index.find("bad_index.gltf"), std::string::npos) << index;
  EXPECT_NE(index.find("exceeds the vertex count"), std::string::npos) << index;
  const std::string absent = load_error("no_such_file.gltf");
  EXPECT_NE(absent.find("no_such_file.gltf"), std::string::npos) << absent;
}
