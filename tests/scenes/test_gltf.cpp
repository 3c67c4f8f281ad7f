// glTF loading: node transforms (TRS hierarchy and matrices), tangents present / derived from UVs /
// from an arbitrary frame, cameras, KHR_lights_punctual, emissive materials, and malformed files.
// The expected values follow from the construction in data/make_data.py.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/scenes/description.h"
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

// A glTF document (as JSON) holding one triangle, vertices (0,0,0), (1,0,0), (0,1,0), as accessor 0
// (POSITION) of mesh 0 in an embedded buffer; no nodes. Tests add nodes and scenes.
nlohmann::json triangle_doc() {
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint8_t> bytes(sizeof p);
  std::memcpy(bytes.data(), p, sizeof p);
  return {{"asset", {{"version", "2.0"}}},
          {"buffers",
           {{{"byteLength", bytes.size()},
             {"uri", "data:application/octet-stream;base64," + base64(bytes)}}}},
          {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", bytes.size()}}}},
          {"accessors",
           {{{"bufferView", 0},
             {"componentType", 5126},
             {"count", 3},
             {"type", "VEC3"},
             {"min", {0, 0, 0}},
             {"max", {1, 1, 0}}}}},
          {"meshes", {{{"name", "tri"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
          {"nodes", nlohmann::json::array()}};
}

std::filesystem::path write_doc(const std::filesystem::path& dir, const std::string& name,
                                const nlohmann::json& doc) {
  const auto path = dir / name;
  std::ofstream(path) << doc.dump();
  return path;
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
  // 3 lux and (2, 1, 1) cd in the file, divided by 683 lm/W (gltf.h).
  EXPECT_EQ(c.lights.directional[0].irradiance, Rgb(3.0 / 683));
  ASSERT_EQ(c.lights.points.size(), 1u);
  expect_near(c.lights.points[0].position, {10, 3, 0}, 1e-9);
  EXPECT_EQ(c.lights.points[0].intensity, Rgb(2.0 / 683, 1.0 / 683, 1.0 / 683));
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

TEST(Gltf, DeepNodeChainLoadsWithoutRecursion) {
  // 10^4 nodes, each the only child of the previous one, the mesh at the bottom; each node moves
  // by (0.001, 0, 0), so the triangle ends at x + 10 (the sum of 10^4 translations).
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    nlohmann::json node = {{"translation", {0.001, 0, 0}}};
    if (i + 1 < n) node["children"] = {i + 1};
    if (i + 1 == n) node["mesh"] = 0, node["name"] = "bottom";
    doc["nodes"].push_back(node);
  }
  doc["scenes"] = {{{"nodes", {0}}}};
  const GltfContent c = load_gltf(write_doc(dir, "chain.gltf", doc));
  ASSERT_EQ(c.meshes.size(), 1u);
  EXPECT_NEAR(c.meshes[0]->bounds().lo.x, 10.0, 1e-6);
  EXPECT_EQ(c.meshes[0]->names.front(), "bottom");
}

TEST(Gltf, NodeWithSeveralParentsIsAnErrorNamingTheNodes) {
  // An instanced DAG that once exploded: 6 levels of 20 nodes, each node listing all 20 of the next
  // level as children (20^6 paths: it hung). glTF requires trees (glTF 2.0, section 3.5.3).
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  const int levels = 6, width = 20;
  // Node 0 is the root; level k holds nodes 1 + (k-1)*width ... k*width.
  doc["nodes"].push_back({{"children", nlohmann::json::array()}});
  for (int k = 1; k <= levels; ++k)
    for (int i = 0; i < width; ++i) doc["nodes"].push_back({{"mesh", 0}});
  for (int i = 0; i < width; ++i) doc["nodes"][0]["children"].push_back(1 + i);
  for (int k = 1; k < levels; ++k)
    for (int i = 0; i < width; ++i)
      for (int j = 0; j < width; ++j)
        doc["nodes"][1 + (k - 1) * width + i]["children"].push_back(1 + k * width + j);
  doc["scenes"] = {{{"nodes", {0}}}};
  const std::string e =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "dag.gltf", doc)); });
  EXPECT_NE(e.find("dag.gltf"), std::string::npos) << e;
  EXPECT_NE(e.find("nodes[21] has several parents (nodes[1] and nodes[2])"), std::string::npos)
      << e;
}

TEST(Gltf, NodeCycleIsAnErrorNamingTheNodes) {
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  doc["nodes"] = {
      {{"mesh", 0}}, {{"children", {2}}}, {{"children", {3}}}, {{"children", {1}}, {"mesh", 0}}};
  doc["scenes"] = {{{"nodes", {0}}}};
  const std::string e =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "cycle.gltf", doc)); });
  EXPECT_NE(e.find("cycle.gltf"), std::string::npos) << e;
  EXPECT_NE(e.find("cycle"), std::string::npos) << e;
  EXPECT_NE(e.find("nodes[1] -> nodes[3] -> nodes[2]"), std::string::npos) << e;
  // A node that is its own child.
  doc["nodes"] = {{{"mesh", 0}, {"children", {0}}}};
  const std::string self =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "self.gltf", doc)); });
  EXPECT_NE(self.find("nodes[0].children[0]"), std::string::npos) << self;
}

TEST(Gltf, AbsurdCameraTransformIsAClearError) {
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  doc["nodes"] = {{{"mesh", 0}}, {{"camera", 0}, {"translation", {1e30, 0, 5}}}};
  doc["scenes"] = {{{"nodes", {0, 1}}}};
  const std::string far =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "far.gltf", doc)); });
  EXPECT_NE(far.find("far.gltf"), std::string::npos) << far;
  EXPECT_NE(far.find("nodes[1]"), std::string::npos) << far;
  EXPECT_NE(far.find("camera position"), std::string::npos) << far;
  // A scale of 1e300 on each of two nested nodes overflows to infinity.
  doc["nodes"] = {{{"mesh", 0}},
                  {{"children", {2}}, {"scale", {1e300, 1e300, 1e300}}},
                  {{"camera", 0}, {"scale", {1e300, 1e300, 1e300}}}};
  const std::string inf =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "inf.gltf", doc)); });
  EXPECT_NE(inf.find("nodes[2]"), std::string::npos) << inf;
  // The same camera 10 m away loads.
  doc["nodes"] = {{{"mesh", 0}}, {{"camera", 0}, {"translation", {0, 0, 10}}}};
  EXPECT_EQ(load_gltf(write_doc(dir, "near.gltf", doc)).cameras.size(), 1u);
}

TEST(Gltf, DescriptionCameraAt1e30IsAClearError) {
  // The scene description's own cameras pass the same check (Camera::look_at).
  const nlohmann::json j = {
      {"objects",
       {{{"type", "quad"}, {"material", "m"}, {"center", {0, 0, 0}}, {"normal", {0, 1, 0}}}}},
      {"materials", {{"m", {{"type", "lambert"}}}}},
      {"camera", {{"type", "perspective"}, {"position", {1e30, 1, 0}}, {"look_at", {0, 0, 0}}}}};
  const std::string e =
      weft::testing::error_of([&] { parse_scene_description(j, ".", "far.json"); });
  EXPECT_NE(e.find("far.json"), std::string::npos) << e;
  EXPECT_NE(e.find("camera position (1e+30, 1, 0) is not finite or beyond 1e+15 m"),
            std::string::npos)
      << e;
  // The field is named once, not once by the camera and again by the description.
  EXPECT_EQ(e.find("field 'camera': field"), std::string::npos) << e;
}

TEST(Gltf, RequiredExtensionsThatWeftCannotReadAreNamed) {
  // Draco-compressed primitives have accessors without bufferViews; the error must say Draco, not
  // "invalid bufferView".
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  doc["nodes"] = {{{"mesh", 0}}};
  doc["scenes"] = {{{"nodes", {0}}}};
  doc["accessors"][0].erase("bufferView");
  doc["meshes"][0]["primitives"][0]["extensions"] = {
      {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
  doc["extensionsUsed"] = {"KHR_draco_mesh_compression", "KHR_lights_punctual"};
  doc["extensionsRequired"] = {"KHR_draco_mesh_compression", "KHR_lights_punctual"};
  const std::string e =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "draco.gltf", doc)); });
  EXPECT_NE(e.find("draco.gltf"), std::string::npos) << e;
  EXPECT_NE(e.find("extensionsRequired"), std::string::npos) << e;
  EXPECT_NE(e.find("KHR_draco_mesh_compression"), std::string::npos) << e;
  EXPECT_EQ(e.find("KHR_lights_punctual,"), std::string::npos) << e;  // that one is supported
}

TEST(Gltf, SparseAccessorSubstitutesItsValues) {
  // sparse.gltf: a quad's four vertices at y = 0, of which the sparse part moves vertices 1 and 3
  // to y = 2 and y = 3 (make_data.py).
  const GltfContent c = load_gltf(kData / "sparse.gltf");
  ASSERT_EQ(c.meshes.size(), 1u);
  const TriangleMesh& m = *c.meshes[0];
  ASSERT_EQ(m.vertex_count(), 4u);
  expect_near(m.position(0), {0, 0, 0}, 0);
  expect_near(m.position(1), {1, 2, 0}, 0);
  expect_near(m.position(2), {1, 0, 1}, 0);
  expect_near(m.position(3), {0, 3, 1}, 0);
  // A sparse accessor without a bufferView starts from zeros.
  const GltfContent z = load_gltf(kData / "sparse_zeros.gltf");
  ASSERT_EQ(z.meshes.size(), 1u);
  expect_near(z.meshes[0]->position(0), {0, 0, 0}, 0);
  expect_near(z.meshes[0]->position(1), {1, 2, 0}, 0);
  expect_near(z.meshes[0]->position(2), {0, 0, 0}, 0);
  expect_near(z.meshes[0]->position(3), {0, 3, 1}, 0);
}

TEST(Gltf, SparseIndicesOutOfOrderAndAbsurdCountsAreErrors) {
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  doc["nodes"] = {{{"mesh", 0}}};
  doc["scenes"] = {{{"nodes", {0}}}};
  // A count that would need 4e18 bytes: refused before anything is allocated.
  doc["accessors"][0]["count"] = 333333333333333333ull;
  const std::string big =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "big.gltf", doc)); });
  EXPECT_NE(big.find("accessors[0]"), std::string::npos) << big;
  EXPECT_NE(big.find("byte range exceeds its bufferView (bufferViews[0], 36 bytes)"),
            std::string::npos)
      << big;
  // The same count without a bufferView (sparse over zeros) has no bytes to bound it.
  doc["accessors"][0].erase("bufferView");
  doc["accessors"][0]["sparse"] = {{"count", 1},
                                   {"indices", {{"bufferView", 0}, {"componentType", 5125}}},
                                   {"values", {{"bufferView", 0}}}};
  const std::string zeros =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "zeros.gltf", doc)); });
  EXPECT_NE(zeros.find("accessors[0].count"), std::string::npos) << zeros;
  // Sparse indices must increase: bytes 0..3 of the buffer read as uint32 index 0, twice.
  doc["accessors"][0]["count"] = 3;
  doc["accessors"][0]["sparse"]["count"] = 2;
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 8}});
  doc["accessors"][0]["sparse"]["indices"]["bufferView"] = 1;
  const std::string order =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "order.gltf", doc)); });
  EXPECT_NE(order.find("accessors[0].sparse.indices"), std::string::npos) << order;
  EXPECT_NE(order.find("not strictly increasing"), std::string::npos) << order;
}

TEST(Gltf, GlbVersionOneAndGltfOneAreRefused) {
  const auto dir = weft::testing::fresh_test_dir();
  // A GLB header of version 1 (glTF 1.0's binary container): magic, version, length, then a JSON
  // chunk that would otherwise parse.
  const std::string json = R"({"asset":{"version":"2.0"}})";
  std::string bytes = "glTF";
  auto u32 = [&](uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
  u32(1);
  u32(static_cast<uint32_t>(20 + json.size()));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);
  bytes += json;
  std::ofstream(dir / "v1.glb", std::ios::binary) << bytes;
  const std::string e = weft::testing::error_of([&] { load_gltf(dir / "v1.glb"); });
  EXPECT_NE(e.find("v1.glb"), std::string::npos) << e;
  EXPECT_NE(e.find("GLB version 1 is not supported"), std::string::npos) << e;
  nlohmann::json doc = triangle_doc();
  doc["asset"]["version"] = "1.0";
  const std::string v1 =
      weft::testing::error_of([&] { load_gltf(write_doc(dir, "v1.gltf", doc)); });
  EXPECT_NE(v1.find("asset.version"), std::string::npos) << v1;
}

TEST(Gltf, DeeplyNestedJsonIsRefusedBeforeTinygltfParsesIt) {
  // Found by fuzzing: 10^5 nested arrays in 'extras' overflowed tinygltf's recursive
  // parser (segfault). Both containers: a .gltf and the JSON chunk of a GLB.
  const auto dir = weft::testing::fresh_test_dir();
  const int n = 100000;
  const std::string json =
      R"({"asset":{"version":"2.0"},"extras":)" + std::string(n, '[') + std::string(n, ']') + "}";
  std::ofstream(dir / "deep.gltf", std::ios::binary) << json;
  const std::string e = weft::testing::error_of([&] { load_gltf(dir / "deep.gltf"); });
  EXPECT_NE(e.find("deep.gltf"), std::string::npos) << e;
  EXPECT_NE(e.find("nested deeper than"), std::string::npos) << e;

  std::string bytes = "glTF";
  auto u32 = [&](uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
  u32(2);
  u32(static_cast<uint32_t>(20 + json.size()));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);  // "JSON"
  bytes += json;
  std::ofstream(dir / "deep.glb", std::ios::binary) << bytes;
  const std::string b = weft::testing::error_of([&] { load_gltf(dir / "deep.glb"); });
  EXPECT_NE(b.find("deep.glb"), std::string::npos) << b;
  EXPECT_NE(b.find("nested deeper than"), std::string::npos) << b;
}

TEST(Gltf, IgnoredContentIsOneWarningPerKind) {
  const auto dir = weft::testing::fresh_test_dir();
  nlohmann::json doc = triangle_doc();
  doc["nodes"] = {{{"mesh", 0}, {"skin", 0}}, {{"mesh", 0}, {"skin", 0}}};
  doc["scenes"] = {{{"nodes", {0, 1}}}};
  doc["materials"] = {
      {{"name", "a"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
      {{"name", "b"}, {"normalTexture", {{"index", 0}}}}};
  doc["meshes"][0]["primitives"][0]["material"] = 0;
  doc["textures"] = {{{"source", 0}}};
  doc["images"] = {{{"uri", "missing.png"}}};
  doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", 0}}, {{"POSITION", 0}}};
  doc["skins"] = {{{"joints", {0}}}};
  doc["animations"] = {
      {{"channels", nlohmann::json::array()}, {"samplers", nlohmann::json::array()}}};
  const GltfContent c = load_gltf(write_doc(dir, "ignored.gltf", doc));
  EXPECT_EQ(c.meshes.size(), 2u);
  auto count = [&](const std::string& what) {
    int n = 0;
    for (const auto& w : c.warnings) n += w.find(what) != std::string::npos ? 1 : 0;
    return n;
  };
  EXPECT_EQ(count("2 glTF material(s)"), 1);
  EXPECT_EQ(count("texture(s)"), 1);
  EXPECT_EQ(count("morph targets"), 1);
  EXPECT_EQ(count("skin(s)"), 1);
  EXPECT_EQ(count("animation(s)"), 1);
  // A file without any of these (the materials only named and coloured) warns about none.
  EXPECT_TRUE(load_gltf(kData / "cube_tangents.gltf").warnings.empty());
}

TEST(Gltf, PhotometricLightsAreConvertedAndDescribed) {
  // blender_sun.gltf: a Blender-style export (make_data.py) with a sun of 1000 lux; the cube's
  // point light is 2 cd in red. Both divided by 683 lm/W (gltf.h).
  const GltfContent c = load_gltf(kData / "blender_sun.gltf");
  ASSERT_EQ(c.lights.directional.size(), 1u);
  EXPECT_DOUBLE_EQ(c.lights.directional[0].irradiance.r, 1000.0 / 683);
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_NE(c.notes[0].find("'Sun' (directional): 1000 lux -> irradiance (1.46413, 1.46413, "
                            "1.46413) W/m^2"),
            std::string::npos)
      << c.notes[0];
  const GltfContent cube = load_gltf(kData / "cube_tangents.gltf");
  ASSERT_EQ(cube.notes.size(), 2u);
  EXPECT_NE(cube.notes[1].find("'bulb' (point): 2 cd -> radiant intensity (0.00292826, "
                               "0.00146413, 0.00146413) W/sr"),
            std::string::npos)
      << cube.notes[1];
  Lights all = cube.lights;
  all.environment = Rgb(0.5);
  const auto lines = describe_lights(all);
  ASSERT_EQ(lines.size(), 3u);
  // (The direction carries the rounding of the light's rotation.)
  EXPECT_EQ(lines[0].find("parallel towards ("), 0u) << lines[0];
  EXPECT_NE(lines[0].find("): irradiance (0.00439239, 0.00439239, 0.00439239) W/m^2"),
            std::string::npos)
      << lines[0];
  EXPECT_EQ(lines[1], "point at (10, 3, 0): intensity (0.00292826, 0.00146413, 0.00146413) W/sr");
  EXPECT_EQ(lines[2], "environment: radiance (0.5, 0.5, 0.5) W m^-2 sr^-1");
}

TEST(Gltf, DescriptionCanSayTheGltfLightsAreRadiometric) {
  // For exporters that write watts (Blender's "Unitless" mode): no division by 683.
  nlohmann::json j = {{"gltf", "blender_sun.gltf"}, {"default_material", {{"type", "lambert"}}}};
  const SceneDescription photometric = parse_scene_description(j, kData, "s.json");
  ASSERT_EQ(photometric.lights.directional.size(), 1u);
  EXPECT_DOUBLE_EQ(photometric.lights.directional[0].irradiance.g, 1000.0 / 683);
  j["gltf_light_units"] = "radiometric";
  const SceneDescription radiometric = parse_scene_description(j, kData, "s.json");
  ASSERT_EQ(radiometric.lights.directional.size(), 1u);
  EXPECT_DOUBLE_EQ(radiometric.lights.directional[0].irradiance.g, 1000.0);
  ASSERT_EQ(radiometric.notes.size(), 1u);
  EXPECT_NE(radiometric.notes[0].find("1000 (radiometric) -> irradiance (1000, 1000, 1000) W/m^2"),
            std::string::npos)
      << radiometric.notes[0];
  j["gltf_light_units"] = "lumens";
  const std::string e =
      weft::testing::error_of([&] { parse_scene_description(j, kData, "s.json"); });
  EXPECT_NE(e.find("gltf_light_units"), std::string::npos) << e;
}
