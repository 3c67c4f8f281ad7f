// Fibers as curves: glTF LINE_STRIP + _RADIUS read back into FiberCurves (the weave generator's
// encoding, weave.h), malformed line primitives, node transforms, inline fiber objects, tubes, and
// the render scene's fiber hits: the point on the surface, the radial normal and fiber frame, the
// fiber's id and segment, and own-fiber exclusion (RenderScene::intersect / occluded with
// ignore_fiber), for round curves and for tubes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/math.h"
#include "weft/scenes/description.h"
#include "weft/scenes/gltf.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;
namespace fs = std::filesystem;
using nlohmann::json;
using weft::testing::error_of;

namespace {

// A glTF document with one node "fiber_node" holding mesh "fiber_mesh": one LINE_STRIP primitive
// through 'points' (x, y, z) with radii 'radii', material "wool". Accessors: 0 POSITION,
// 1 _RADIUS; the test edits the JSON for malformed cases.
json line_strip_gltf(const std::vector<float>& points, const std::vector<float>& radii) {
  std::vector<uint8_t> bin(4 * (points.size() + radii.size()));
  std::memcpy(bin.data(), points.data(), 4 * points.size());
  std::memcpy(bin.data() + 4 * points.size(), radii.data(), 4 * radii.size());
  json j;
  j["asset"] = {{"version", "2.0"}};
  j["scene"] = 0;
  j["scenes"] = json::array({{{"nodes", {0}}}});
  j["nodes"] = json::array({{{"name", "fiber_node"}, {"mesh", 0}}});
  j["materials"] = json::array({{{"name", "wool"}}});
  j["meshes"] =
      json::array({{{"name", "fiber_mesh"},
                    {"primitives", json::array({{{"attributes", {{"POSITION", 0}, {"_RADIUS", 1}}},
                                                 {"material", 0},
                                                 {"mode", 3}}})}}});
  j["accessors"] = json::array(
      {{{"bufferView", 0}, {"componentType", 5126}, {"count", points.size() / 3}, {"type", "VEC3"}},
       {{"bufferView", 1}, {"componentType", 5126}, {"count", radii.size()}, {"type", "SCALAR"}}});
  j["bufferViews"] = json::array(
      {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 4 * points.size()}},
       {{"buffer", 0}, {"byteOffset", 4 * points.size()}, {"byteLength", 4 * radii.size()}}});
  j["buffers"] = json::array({{{"byteLength", bin.size()},
                               {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
  return j;
}

const std::vector<float> kPoints = {0, 0, 0, 1, 0, 0, 2, 0.5f, 0};
const std::vector<float> kRadii = {0.1f, 0.1f, 0.2f};

fs::path write_json(const json& j, const std::string& name) {
  const fs::path p = weft::testing::fresh_test_dir() / name;
  std::ofstream(p) << j.dump();
  return p;
}

// The curves of every FiberCurves in order, as one (the loader makes one per mesh instance).
FiberCurves concatenate(const std::vector<std::shared_ptr<const FiberCurves>>& sets) {
  FiberCurves out;
  for (const auto& s : sets)
    for (size_t c = 0; c < s->curve_count(); ++c) {
      out.curve_first.push_back(static_cast<uint32_t>(out.point_count()));
      out.curve_points.push_back(s->curve_points[c]);
      const auto it = std::find(out.yarn_material.begin(), out.yarn_material.end(), s->material(c));
      out.curve_yarn.push_back(static_cast<uint32_t>(it - out.yarn_material.begin()));
      if (it == out.yarn_material.end()) out.yarn_material.push_back(s->material(c));
      const size_t first = s->curve_first[c];
      out.points.insert(out.points.end(), s->points.begin() + 4 * first,
                        s->points.begin() + 4 * (first + s->curve_points[c]));
    }
  return out;
}

// A description of straight inline fibers along x at heights z (radius r), material "fiber",
// lit by nothing: for geometric queries.
SceneDescription fibers_along_x(const std::vector<double>& z, double r, const char* geometry,
                                int segments = 4) {
  json objs = json::array();
  for (size_t i = 0; i < z.size(); ++i)
    objs.push_back({{"type", "fiber"},
                    {"name", std::string("f").append(std::to_string(i))},
                    {"material", "fiber"},
                    {"from", {-10, 0, z[i]}},
                    {"to", {10, 0, z[i]}},
                    {"radius", r},
                    {"segments", segments}});
  const json j = {{"objects", objs},
                  {"materials", {{"fiber", {{"type", "lambert"}}}}},
                  {"fiber_geometry", {{"type", geometry}}}};
  return parse_scene_description(j, ".", "fibers.json");
}

}  // namespace

TEST(Curves, FiberDetailWovenSampleRoundTripsThroughGltf) {
  WeaveOptions o = red_cotton_weave_options();
  o.detail = "fiber";
  o.pattern = "twill:2/1";
  const WovenSample s = make_woven_sample(o);
  ASSERT_GT(s.fibers.curve_count(), 10u);
  const fs::path dir = weft::testing::fresh_test_dir();
  for (const char* name : {"fibers.glb", "fibers.gltf"}) {
    SCOPED_TRACE(name);
    write_woven(dir / name, s);
    const GltfContent c = load_gltf(dir / name);
    EXPECT_TRUE(c.meshes.empty());
    EXPECT_TRUE(c.warnings.empty()) << c.warnings.front();
    // One set per yarn node, named like meshes: node, ancestor "patch", glTF mesh.
    ASSERT_EQ(c.curves.size(), s.fibers.yarn_material.size());
    for (const auto& set : c.curves) {
      EXPECT_TRUE(set->has_name("patch"));
      ASSERT_EQ(set->names.size(), 3u);
      EXPECT_EQ(set->names[0], set->names[2]);  // node "warp_0" holds mesh "warp_0"
    }
    const FiberCurves back = concatenate(c.curves);
    EXPECT_EQ(back.points, s.fibers.points);  // float in, float out: bit for bit
    EXPECT_EQ(back.curve_first, s.fibers.curve_first);
    EXPECT_EQ(back.curve_points, s.fibers.curve_points);
    for (size_t k = 0; k < s.fibers.curve_count(); ++k)
      ASSERT_EQ(back.material(k), s.fibers.material(k)) << k;
  }
  // Through a scene description: the fibers are shapes after the meshes, selected by name, bound
  // by material key, and framed with their radii.
  const json j = {
      {"gltf", "fibers.glb"},
      {"materials", {{"warp", {{"type", "lambert"}}}, {"weft", {{"type", "lambert"}}}}}};
  const SceneDescription d = parse_scene_description(j, dir, "weave.json");
  EXPECT_EQ(d.shape_count(), d.curves.size());
  EXPECT_EQ(d.select_object("patch"), std::vector<uint8_t>(d.curves.size(), 1));
  const auto warp0 = d.select_object("warp_0");
  EXPECT_EQ(std::count(warp0.begin(), warp0.end(), 1), 1);
  const Bounds3 b = d.object_bounds("patch"), f = s.fibers.bounds();
  EXPECT_EQ(b.lo, f.lo);
  EXPECT_EQ(b.hi, f.hi);
  // The bounds include the radii: the sample's thickness as the generator reports it.
  EXPECT_NEAR(b.lo.y * 1e3, s.summary.y_min_mm, 1e-6);
  EXPECT_NEAR(b.hi.y * 1e3, s.summary.y_max_mm, 1e-6);
  // A fiber material without a binding is an error, as for meshes.
  const json unbound = {{"gltf", "fibers.glb"}, {"materials", {{"warp", {{"type", "lambert"}}}}}};
  EXPECT_NE(error_of([&] {
              parse_scene_description(unbound, dir, "weave.json");
            }).find("no binding for glTF material 'weft'"),
            std::string::npos);
}

TEST(Curves, NodeTransformMovesPointsAndScalesRadii) {
  json j = line_strip_gltf(kPoints, kRadii);
  // Uniform scale 2, a quarter turn about y (x -> -z), then a shift.
  const double h = std::sqrt(0.5);
  j["nodes"][0]["scale"] = {2, 2, 2};
  j["nodes"][0]["rotation"] = {0, h, 0, h};
  j["nodes"][0]["translation"] = {1, 2, 3};
  const GltfContent c = load_gltf(write_json(j, "t.gltf"));
  ASSERT_EQ(c.curves.size(), 1u);
  const FiberCurves& f = *c.curves[0];
  ASSERT_EQ(f.curve_count(), 1u);
  ASSERT_EQ(f.point_count(), 3u);
  EXPECT_EQ(f.material(0), "wool");
  EXPECT_EQ(f.names, (std::vector<std::string>{"fiber_node", "fiber_mesh"}));
  const Vec3 expect[3] = {{1, 2, 3}, {1, 2, 1}, {1, 3, -1}};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(length(f.point(k) - expect[k]), 0, 1e-6) << k;
    EXPECT_NEAR(f.radius(k), 2 * kRadii[k], 1e-7) << k;
  }
  // A mirror is a uniform scale too: radii stay positive.
  j["nodes"][0].erase("rotation");
  j["nodes"][0]["scale"] = {-0.5, 0.5, 0.5};
  const GltfContent m = load_gltf(write_json(j, "m.gltf"));
  EXPECT_NEAR(m.curves[0]->radius(2), 0.1, 1e-7);
  EXPECT_NEAR(m.curves[0]->point(1).x, 1 - 0.5, 1e-6);
}

TEST(Curves, MalformedLinePrimitivesAreErrorsNamingTheField) {
  auto error = [](const json& j) {
    return error_of([&] { load_gltf(write_json(j, "bad.gltf")); });
  };
  auto expect_error = [&](const json& j, const std::string& field, const std::string& what) {
    const std::string e = error(j);
    EXPECT_NE(e.find("bad.gltf"), std::string::npos) << e;
    EXPECT_NE(e.find("field '" + field + "'"), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  const std::string prim = "meshes[0].primitives[0]";
  {  // fewer radii than points
    json j = line_strip_gltf(kPoints, kRadii);
    j["accessors"][1]["count"] = 2;
    expect_error(j, prim + ".attributes._RADIUS", "differs from POSITION");
  }
  {  // a radius per point, but as VEC3
    json j = line_strip_gltf(kPoints, {0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f});
    j["accessors"][1]["type"] = "VEC3";
    j["accessors"][1]["count"] = 3;
    expect_error(j, prim + ".attributes._RADIUS", "SCALAR");
  }
  {  // integers are not metres
    json j = line_strip_gltf(kPoints, kRadii);
    j["accessors"][1]["componentType"] = 5123;
    expect_error(j, prim + ".attributes._RADIUS", "float");
  }
  // Zero, negative and non-finite radii.
  expect_error(line_strip_gltf(kPoints, {0.1f, 0.0f, 0.1f}), prim + ".attributes._RADIUS",
               "element 1 must be > 0");
  expect_error(line_strip_gltf(kPoints, {0.1f, 0.1f, -0.1f}), prim + ".attributes._RADIUS",
               "element 2 must be > 0");
  expect_error(line_strip_gltf(kPoints, {0.1f, NAN, 0.1f}), prim + ".attributes._RADIUS",
               "non-finite");
  // One point is no fiber.
  expect_error(line_strip_gltf({0, 0, 0}, {0.1f}), prim, "at least 2 points");
  {  // indices past the points
    json j = line_strip_gltf(kPoints, kRadii);
    std::vector<uint8_t> idx = {0, 5};
    j["buffers"].push_back(
        {{"byteLength", 2}, {"uri", "data:application/octet-stream;base64," + base64(idx)}});
    j["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 2}});
    j["accessors"].push_back(
        {{"bufferView", 2}, {"componentType", 5121}, {"count", 2}, {"type", "SCALAR"}});
    j["meshes"][0]["primitives"][0]["indices"] = 2;
    expect_error(j, prim + ".indices", "exceeds the vertex count 3");
  }
  {  // an accessor that claims more points than its buffer holds: refused before reading
    json j = line_strip_gltf(kPoints, kRadii);
    j["accessors"][0]["count"] = uint64_t(1) << 39;
    j["accessors"][1]["count"] = uint64_t(1) << 39;
    expect_error(j, "accessors[0]", "exceeds its bufferView");
  }
  {  // a non-uniform scale would make the round fiber elliptic: the node is named
    json j = line_strip_gltf(kPoints, kRadii);
    j["nodes"][0]["scale"] = {1, 2, 1};
    expect_error(j, "nodes[0]", "uniform scale");
  }
  {  // _RADIUS index out of range
    json j = line_strip_gltf(kPoints, kRadii);
    j["meshes"][0]["primitives"][0]["attributes"]["_RADIUS"] = 7;
    expect_error(j, prim + ".attributes._RADIUS", "out of range");
  }
  // Lines without _RADIUS keep the warning (no area, skipped); so do radii on plain LINES.
  json plain = line_strip_gltf(kPoints, kRadii);
  plain["meshes"][0]["primitives"][0]["attributes"].erase("_RADIUS");
  const GltfContent p = load_gltf(write_json(plain, "plain.gltf"));
  EXPECT_TRUE(p.curves.empty());
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_NE(p.warnings[0].find(prim + ": points/lines carry no area; skipped"), std::string::npos);
  json lines = line_strip_gltf({0, 0, 0, 1, 0, 0}, {0.1f, 0.1f});
  lines["meshes"][0]["primitives"][0]["mode"] = 1;
  const GltfContent l = load_gltf(write_json(lines, "lines.gltf"));
  EXPECT_TRUE(l.curves.empty());
  ASSERT_EQ(l.warnings.size(), 1u);
  EXPECT_NE(l.warnings[0].find("LINE_STRIP"), std::string::npos);
}

TEST(Curves, InlineFiberObjectsAndTheirErrors) {
  const SceneDescription d = fibers_along_x({0, 1}, 0.25, "tubes", 3);
  ASSERT_EQ(d.curves.size(), 2u);
  EXPECT_TRUE(d.meshes.empty());
  EXPECT_EQ(d.fiber_geometry.type, FiberGeometry::Type::tubes);
  EXPECT_EQ(d.fiber_geometry.tube_sides, 8);
  const FiberCurves& f = *d.curves[1];
  EXPECT_EQ(f.point_count(), 4u);
  EXPECT_EQ(f.names, std::vector<std::string>{"f1"});
  EXPECT_EQ(f.material(0), "fiber");
  EXPECT_NEAR(length(f.point(1) - Vec3{-10 + 20.0 / 3, 0, 1}), 0, 1e-5);
  EXPECT_EQ(d.select_object("f1"), (std::vector<uint8_t>{0, 1}));
  const Bounds3 b = d.object_bounds("f0");
  EXPECT_NEAR(b.lo.y, -0.25, 1e-7);
  EXPECT_NEAR(b.hi.x, 10.25, 1e-6);

  auto error = [](json object, const json& extra = json::object()) {
    json j = {{"objects", {object}}, {"default_material", {{"type", "lambert"}}}};
    j.update(extra);
    return error_of([&] { parse_scene_description(j, ".", "s.json"); });
  };
  const json fiber = {{"type", "fiber"},
                      {"material", "m"},
                      {"from", {0, 0, 0}},
                      {"to", {1, 0, 0}},
                      {"radius", 0.1}};
  EXPECT_EQ(error(fiber), "");
  json bad = fiber;
  bad["radius"] = 0;
  EXPECT_NE(error(bad).find("field 'objects[0].radius'"), std::string::npos);
  bad = fiber;
  bad["to"] = {0, 0, 0};
  EXPECT_NE(error(bad).find("field 'objects[0].to'"), std::string::npos);
  EXPECT_NE(error(fiber, {{"fiber_geometry", {{"type", "tubes"}, {"sides", 2}}}})
                .find("field 'fiber_geometry.sides'"),
            std::string::npos);
  // Sides mean nothing to round curves: an error, not a silent no-op.
  EXPECT_NE(error(fiber, {{"fiber_geometry", {{"type", "curves"}, {"sides", 6}}}})
                .find("fiber_geometry.sides"),
            std::string::npos);
  EXPECT_NE(error(fiber, {{"fiber_geometry", {{"type", "ribbons"}}}}).find("fiber_geometry.type"),
            std::string::npos);
}

TEST(Curves, TubesCloseAroundEachFiberWithTheCirclesMeanWidth) {
  const SceneDescription d = fibers_along_x({0, 3}, 0.5, "curves", 5);
  FiberCurves both = concatenate(d.curves);
  for (int sides : {3, 8}) {
    SCOPED_TRACE(sides);
    const FiberTubes t = make_fiber_tubes(both, sides);
    const TriangleMesh& m = t.mesh;
    ASSERT_EQ(m.triangle_count(), 2u * sides * both.segment_count());
    ASSERT_EQ(t.triangle_segment.size(), m.triangle_count());
    ASSERT_EQ(t.curve_first_triangle, (std::vector<uint32_t>{0, uint32_t(2 * sides * 5)}));
    // Circumradius r pi / (n sin(pi / n)): the polygon's perimeter is the circle's, 2 pi r.
    const double rho = 0.5 * kPi / (sides * std::sin(kPi / sides));
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      const Vec3 p = m.position(v);
      const double z0 = p.z > 1.5 ? 3 : 0;
      EXPECT_NEAR(std::hypot(p.y, p.z - z0), rho, 1e-6);
      const Vec3 n{m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]};
      EXPECT_NEAR(dot(n, normalize(Vec3{0, p.y, p.z - z0})), 1, 1e-6);
      EXPECT_EQ(m.tangents[4 * v], 1.0f);
    }
    for (size_t tri = 0; tri < m.triangle_count(); ++tri) {
      const Vec3 p0 = m.position(m.indices[3 * tri]);
      const Vec3 ng =
          cross(m.position(m.indices[3 * tri + 1]) - p0, m.position(m.indices[3 * tri + 2]) - p0);
      const double z0 = p0.z > 1.5 ? 3 : 0;
      EXPECT_GT(dot(ng, Vec3{0, p0.y, p0.z - z0}), 0) << "outward, counter-clockwise";
      EXPECT_EQ(t.triangle_segment[tri] / 5, tri < 2u * sides * 5 ? 0u : 1u);
    }
  }
  EXPECT_THROW(make_fiber_tubes(both, 2), Error);
}

TEST(Curves, HitsOnFibersCarryTheSurfacePointFrameAndFiber) {
  const double r = 0.25;
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    const bool round = std::string(geometry) == "curves";
    const SceneDescription d = fibers_along_x({0, 2}, r, geometry);
    const RenderScene scene(d);
    EXPECT_EQ(scene.fiber_count(), 2u);
    EXPECT_EQ(scene.shape_count(), 2u);
    EXPECT_EQ(scene.mesh_count(), 0u);
    EXPECT_EQ(scene.curve_segment_count(), round ? 8u : 0u);
    EXPECT_EQ(scene.triangle_count(), round ? 0u : 2u * 8 * 8);
    int hits = 0;
    for (int k = 0; k < 200; ++k) {
      Rng rng(5, uint64_t(k));
      // Rays from above at random angles towards a random point on fiber 1's axis.
      const Vec3 target{-3 + 6 * rng.uniform(), 0, 2};
      const Vec3 from =
          target + Vec3{rng.uniform() - 0.5, 2 + rng.uniform(), 0.8 * (rng.uniform() - 0.5)} * 3;
      const Vec3 d0 = normalize(target - from);
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect({from, d0}, &hit));
      ++hits;
      EXPECT_EQ(hit.fiber, 1);
      EXPECT_EQ(hit.shape, 1u);
      EXPECT_EQ(hit.segment, static_cast<uint32_t>(std::floor((hit.p.x + 10) / 5)));
      const FiberSegment seg = scene.fiber_segment(hit);
      EXPECT_NEAR(seg.p0.x, -10 + 5.0 * hit.segment, 1e-5);
      EXPECT_NEAR(seg.r0, r, 1e-7);
      const Vec3 radial{0, hit.p.y, hit.p.z - 2};
      // The fiber frame: x along the fiber, z radial and outward, y = z x x.
      EXPECT_NEAR(hit.shading.s.x, 1, 1e-6);
      EXPECT_NEAR(dot(hit.shading.n, normalize(radial)), 1, round ? 1e-9 : 1e-6);
      EXPECT_NEAR(length(hit.shading.t - cross(hit.shading.n, hit.shading.s)), 0, 1e-12);
      EXPECT_GT(dot(hit.ng, -d0), 0);
      if (round) {
        // On the cylinder (double precision, not Embree's float distance), radial normal.
        EXPECT_NEAR(length(radial), r, 1e-12);
        EXPECT_NEAR(length(hit.ng - radial / r), 0, 1e-12);
        EXPECT_NEAR(length(hit.p - (from + d0 * hit.t)), 0, 1e-5);
      }
      EXPECT_EQ(scene.fiber_ref(hit.fiber).shape, hit.shape);
      // Where the ray, continued, leaves fiber 1: the far root of the cylinder.
      const auto exit = cylinder_exit_distance(seg, hit.p, d0);
      ASSERT_TRUE(exit.has_value());
      const Vec3 out = hit.p + d0 * *exit;
      EXPECT_NEAR(std::hypot(out.y, out.z - 2), r, 1e-9);
      EXPECT_GT(*exit, round ? -1e-9 : -0.1 * r);
    }
    EXPECT_EQ(hits, 200);
    EXPECT_THROW(scene.fiber_ref(2), Error);
    EXPECT_EQ(scene.fiber_segments(0).size(), 4u);
  }
  // A line through the axis of a unit cylinder, perpendicular to it, leaves 2 r after entering.
  const FiberSegment s{{0, 0, 0}, {1, 0, 0}, 0.5, 0.5};
  EXPECT_NEAR(*cylinder_exit_distance(s, {0.5, 0, -0.5}, {0, 0, 1}), 1.0, 1e-15);
  EXPECT_NEAR(*cylinder_exit_distance(s, {0.5, 0, 0}, normalize(Vec3{1, 0, 1})),
              0.5 * std::sqrt(2.0), 1e-15);
  EXPECT_FALSE(cylinder_exit_distance(s, {0.5, 0, -2}, {1, 0, 0}).has_value());  // along the axis
  EXPECT_FALSE(cylinder_exit_distance(s, {0.5, 1, -2}, {0, 0, 1}).has_value());  // misses
}

TEST(Curves, RaysLeavingAFiberIgnoreItButNotTheOthers) {
  // Fiber 0 at z = 0, fiber 1 at z = -1 (behind fiber 0 seen from +z), radius 0.25. A point B on
  // top of fiber 0 (towards +z) sends a shadow ray to a light far behind it, along -z: it crosses
  // its own fiber, then fiber 1.
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    const RenderScene two(fibers_along_x({0, -1}, 0.25, geometry));
    const RenderScene one(fibers_along_x({0}, 0.25, geometry));
    SurfaceHit b;
    ASSERT_TRUE(two.intersect({{0.3, 0, 5}, {0, 0, -1}}, &b));
    ASSERT_EQ(b.fiber, 0);
    const Vec3 to_light{0, 0, -1};
    const Vec3 o = b.spawn_origin(to_light);
    // Alone, fiber 0 does not shadow its own point; without the exclusion it would.
    EXPECT_FALSE(one.occluded(o, to_light, 1e300, b.fiber));
    EXPECT_TRUE(one.occluded(o, to_light, 1e300));
    // Another fiber behind it does shadow it.
    EXPECT_TRUE(two.occluded(o, to_light, 1e300, b.fiber));
    EXPECT_FALSE(two.occluded(o, to_light, 0.5, b.fiber));  // ends before fiber 1
    // Ignoring one fiber leaves every other in the way: from above fiber 0 (top at z = 0.25),
    // fiber 1's top is 1.75 away.
    EXPECT_TRUE(two.occluded({0.3, 0, 1}, to_light, 1.0, 1));
    EXPECT_FALSE(two.occluded({0.3, 0, 1}, to_light, 1.0, 0));
    EXPECT_TRUE(two.occluded({0.3, 0, 1}, to_light, 2.0, 0));
    // The continuation ray passes through its own fiber and meets fiber 1's near side.
    SurfaceHit next;
    ASSERT_TRUE(two.intersect({o, to_light}, &next, b.fiber));
    EXPECT_EQ(next.fiber, 1);
    EXPECT_NEAR(next.p.z, -0.75, 0.25 * (1 - std::cos(kPi / 8)) + 1e-6);
    EXPECT_FALSE(one.intersect({o, to_light}, &next, b.fiber));
    // Grazing and oblique rays through the own fiber are all let through.
    for (int k = 0; k < 100; ++k) {
      Rng rng(9, uint64_t(k));
      const double phi = 2 * kPi * rng.uniform(), s = 2 * rng.uniform() - 1;
      const Vec3 dir{s, std::sqrt(1 - s * s) * std::cos(phi), std::sqrt(1 - s * s) * std::sin(phi)};
      ASSERT_FALSE(one.occluded(b.spawn_origin(dir), dir, 1e300, b.fiber)) << k;
    }
  }
}

TEST(Curves, RaysLeavingAFiberPassThroughItsNextPiece) {
  // One fiber along x (radius 0.25) whole, or cut at x = 0 into two curves whose end spheres
  // overlap there (as the tiles of a woven sample join a fiber to its continuation in the next
  // repeat), and a second fiber below it at z = -1. A ray from a point of the fiber's first
  // piece that runs through its body across x = 0 must go on as through the whole fiber: the next
  // piece, met from inside, is neither a hit nor a blocker (it was both: the whole-fiber table's
  // light from behind stopped at every joint). The other fiber still stops it.
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    auto scene = [&](const std::vector<std::pair<double, double>>& pieces) {
      json objs = json::array();
      for (size_t i = 0; i < pieces.size(); ++i)
        objs.push_back({{"type", "fiber"},
                        {"name", "f" + std::to_string(i)},
                        {"material", "fiber"},
                        {"from", {pieces[i].first, 0, 0}},
                        {"to", {pieces[i].second, 0, 0}},
                        {"radius", 0.25},
                        {"segments", 2}});
      objs.push_back({{"type", "fiber"},
                      {"name", "below"},
                      {"material", "fiber"},
                      {"from", {-10, 0, -1}},
                      {"to", {10, 0, -1}},
                      {"radius", 0.25},
                      {"segments", 4}});
      const json j = {{"objects", objs},
                      {"materials", {{"fiber", {{"type", "lambert"}}}}},
                      {"fiber_geometry", {{"type", geometry}}}};
      return RenderScene(parse_scene_description(j, ".", "pieces.json"));
    };
    const RenderScene whole = scene({{-10, 10}}), cut = scene({{-10, 0}, {0, 10}});
    int crossing = 0, below = 0;
    for (int k = 0; k < 400; ++k) {
      Rng rng(11, uint64_t(k));
      // A point B on the first piece near the joint, seen from above.
      const double x = -0.6 * rng.uniform(), phi = kPi * (0.1 + 0.8 * rng.uniform());
      const Vec3 from{x, 5 * std::cos(phi), 5 * std::sin(phi)};
      SurfaceHit b;
      ASSERT_TRUE(cut.intersect({from, normalize(Vec3{x, 0, 0} - from)}, &b));
      ASSERT_EQ(b.fiber, 0);
      // Into the fiber's body, towards +x (so along a chord that may cross the joint).
      const double s = 0.3 + 0.65 * rng.uniform(), psi = 2 * kPi * rng.uniform();
      Vec3 d{s, std::sqrt(1 - s * s) * std::cos(psi), std::sqrt(1 - s * s) * std::sin(psi)};
      if (dot(d, b.ng) > 0) d = d - b.ng * (2 * dot(d, b.ng));
      d.x = std::abs(d.x);
      const Vec3 o = b.spawn_origin(d);
      const auto chord = cylinder_exit_distance({{-10, 0, 0}, {10, 0, 0}, 0.25, 0.25}, o, d);
      if (chord && o.x + d.x * *chord > 0) ++crossing;
      SurfaceHit hw, hc;
      const bool w = whole.intersect({o, d}, &hw, 0), c = cut.intersect({o, d}, &hc, 0);
      ASSERT_EQ(w, c) << k;
      if (w) {
        EXPECT_EQ(hw.fiber, 1) << k;  // the fiber below: ids 1 (whole) and 2 (cut)
        EXPECT_EQ(hc.fiber, 2) << k;
        EXPECT_NEAR(hw.t, hc.t, 1e-9) << k;
        ++below;
      }
      EXPECT_EQ(whole.occluded(o, d, 1e300, 0), cut.occluded(o, d, 1e300, 0)) << k;
      EXPECT_FALSE(cut.occluded(o, d, 3.0 * 0.25, 0)) << k;  // nothing within its own body
    }
    EXPECT_GT(crossing, 100);  // the test crosses the joint often
    EXPECT_GT(below, 50);      // and still meets the other fiber
  }
}

TEST(Curves, MeshesAndCurvesTogetherKeepTheirIds) {
  // A quad (shape 0) and two inline fibers (shapes 1, 2): mesh hits have no fiber, fiber ids
  // count the curves across sets.
  const json j = {{"objects",
                   {{{"type", "quad"},
                     {"name", "floor"},
                     {"material", "m"},
                     {"center", {0, -1, 0}},
                     {"normal", {0, 1, 0}},
                     {"size", {50, 50}}},
                    {{"type", "fiber"},
                     {"name", "a"},
                     {"material", "m"},
                     {"from", {-5, 0, 0}},
                     {"to", {5, 0, 0}},
                     {"radius", 0.1}},
                    {{"type", "fiber"},
                     {"name", "b"},
                     {"material", "m"},
                     {"from", {-5, 0, 1}},
                     {"to", {5, 0, 1}},
                     {"radius", 0.1}}}},
                  {"materials", {{"m", {{"type", "lambert"}}}}}};
  const SceneDescription d = parse_scene_description(j, ".", "mixed.json");
  EXPECT_EQ(d.select_object("b"), (std::vector<uint8_t>{0, 0, 1}));
  const RenderScene scene(d);
  SurfaceHit h;
  ASSERT_TRUE(scene.intersect({{0, 5, 1}, {0, -1, 0}}, &h));
  EXPECT_EQ(h.shape, 2u);
  EXPECT_EQ(h.fiber, 1);
  ASSERT_TRUE(scene.intersect({{0, 5, 0.5}, {0, -1, 0}}, &h));
  EXPECT_EQ(h.shape, 0u);
  EXPECT_EQ(h.fiber, kNoFiber);
  EXPECT_FALSE(h.on_fiber());
  EXPECT_THROW(scene.fiber_segment(h), Error);
  // Ignoring a fiber never hides a mesh.
  ASSERT_TRUE(scene.intersect({{0, 5, 1}, {0, -1, 0}}, &h, 1));
  EXPECT_EQ(h.shape, 0u);
  // Override masks cover every shape.
  RenderSceneOptions o;
  o.override_shapes = {1, 0};
  EXPECT_THROW(RenderScene(d, o), Error);
}

// A curve set's own work polls the build's callback (between geometries it asks with no total;
// Embree's monitor gives a total of 1000): its segment index and Embree buffers every few million
// entries, so that a set near the limit of 3e7 points, hundreds of MB of new pages, is stopped
// within it. Polled without a stop, the scene is whole; stopped at any of those polls, cancelled.
TEST(Curves, ALargeCurveSetPollsWhileItIsCopied) {
  // 3 M points: 3072 straight fibers of 1024 points side by side.
  constexpr uint32_t kCurves = 3072, kPointsPerCurve = 1024;
  auto curves = std::make_shared<FiberCurves>();
  curves->points.reserve(4 * size_t(kCurves) * kPointsPerCurve);
  for (uint32_t c = 0; c < kCurves; ++c) {
    curves->curve_first.push_back(c * kPointsPerCurve);
    curves->curve_points.push_back(kPointsPerCurve);
    curves->curve_yarn.push_back(0);
    for (uint32_t i = 0; i < kPointsPerCurve; ++i)
      curves->points.insert(curves->points.end(), {float(i) * 1e-3f, 0, float(c) * 1e-3f, 1e-4f});
  }
  curves->yarn_material = {"m"};
  SceneDescription d;
  d.source = "long.json";
  d.curves.push_back(curves);
  MaterialBinding any;
  any.type = "lambert";
  d.default_material = any;
  int between = 0;  // asks without a total: between geometries and within the curve set
  RenderSceneOptions counted;
  counted.build_progress = [&](const ProgressUpdate& u) {
    between += u.total == 0;
    return true;
  };
  const RenderScene whole(d, counted);
  EXPECT_FALSE(whole.cancelled());
  // Before the set, then 3 M segments indexed (3 asks), 12 M floats copied (6) and 3 M flags (1).
  EXPECT_GE(between, 1 + 3 + 6 + 1);
  for (const int stop_at : {2, 5, between - 1}) {
    SCOPED_TRACE(stop_at);
    int asked = 0;
    RenderSceneOptions stopping;
    stopping.build_progress = [&](const ProgressUpdate& u) {
      return !(u.total == 0 && ++asked >= stop_at);
    };
    EXPECT_TRUE(RenderScene(d, stopping).cancelled());
  }
}
