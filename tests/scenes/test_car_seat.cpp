// The car-seat generator (scenes/car_seat.h):
//  * every part is a closed, consistently wound surface: welded by position, each directed edge
//    occurs once and its reverse once; the enclosed volume is positive (outward winding); the
//    Euler characteristic is 2 for the rounded boxes (spheres) and 0 for the piping (a torus);
//  * no part intersects itself: every pair of triangles that share no vertex and whose boxes
//    overlap is tested edge against triangle (Moller and Trumbore 1997);
//  * frames: unit normals perpendicular to the tangents (mesh_checks.h), and where the panel's
//    warp axis lies in the surface the tangent follows it;
//  * the triangle count stays within a few hundred thousand at the default grid;
//  * the glTF it writes loads back with the same parts, materials and counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "mesh_checks.h"
#include "weft/core/error.h"
#include "weft/scenes/car_seat.h"
#include "weft/scenes/description.h"
#include "weft/scenes/gltf.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {

// A coarse seat keeps the all-pairs checks quick; the construction does not depend on the cell.
const CarSeat& coarse_seat() {
  static const CarSeat seat = [] {
    CarSeatOptions o;
    o.cell_mm = 12;
    return make_car_seat(o);
  }();
  return seat;
}

// Vertex ids after welding equal positions.
std::vector<uint32_t> weld(const TriangleMesh& m, size_t* unique = nullptr) {
  std::map<std::array<float, 3>, uint32_t> ids;
  std::vector<uint32_t> out(m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v)
    out[v] = ids.emplace(std::array<float, 3>{m.positions[3 * v], m.positions[3 * v + 1],
                                              m.positions[3 * v + 2]},
                         uint32_t(ids.size()))
                 .first->second;
  if (unique) *unique = ids.size();
  return out;
}

// Whether the segment a-b crosses the plane of triangle (p0, p1, p2) inside it, ends included.
// Segments (nearly) in the triangle's plane are left to coplanar_overlap.
bool segment_hits_triangle(const Vec3& a, const Vec3& b, const Vec3& p0, const Vec3& p1,
                           const Vec3& p2) {
  const Vec3 d = b - a, e1 = p1 - p0, e2 = p2 - p0;
  const Vec3 h = cross(d, e2);
  const double det = dot(e1, h);
  if (std::abs(det) <= 1e-6 * length(d) * length(e1) * length(e2)) return false;
  const Vec3 s = a - p0;
  const double u = dot(s, h) / det;
  if (u < 0 || u > 1) return false;
  const Vec3 q = cross(s, e1);
  const double v = dot(d, q) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = dot(e2, q) / det;
  return t >= 0 && t <= 1;
}

// Whether two triangles lying in one plane (within float rounding) overlap: in the plane's
// dominant projection, an edge of one properly crosses an edge of the other, or a vertex of one
// lies strictly inside the other.
bool coplanar_overlap(const Vec3 (&a)[3], const Vec3 (&b)[3]) {
  const Vec3 n = cross(a[1] - a[0], a[2] - a[0]);
  const double scale = length(n);
  if (!(scale > 0)) return false;
  for (const Vec3& p : b)
    if (std::abs(dot(p - a[0], n)) > 1e-5 * scale * std::sqrt(scale)) return false;
  const int drop = std::abs(n.x) > std::abs(n.y) ? (std::abs(n.x) > std::abs(n.z) ? 0 : 2)
                                                 : (std::abs(n.y) > std::abs(n.z) ? 1 : 2);
  auto p2 = [drop](const Vec3& p) {
    return drop == 0 ? Vec2{p.y, p.z} : (drop == 1 ? Vec2{p.z, p.x} : Vec2{p.x, p.y});
  };
  auto orient = [](Vec2 p, Vec2 q, Vec2 r) {
    return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
  };
  Vec2 A[3], B[3];
  for (int k = 0; k < 3; ++k) A[k] = p2(a[k]), B[k] = p2(b[k]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vec2 p = A[i], q = A[(i + 1) % 3], r = B[j], s = B[(j + 1) % 3];
      if (orient(p, q, r) * orient(p, q, s) < 0 && orient(r, s, p) * orient(r, s, q) < 0)
        return true;
    }
  auto inside = [&](const Vec2(&T)[3], Vec2 p) {
    const double o0 = orient(T[0], T[1], p), o1 = orient(T[1], T[2], p), o2 = orient(T[2], T[0], p);
    return (o0 > 0 && o1 > 0 && o2 > 0) || (o0 < 0 && o1 < 0 && o2 < 0);
  };
  for (int k = 0; k < 3; ++k)
    if (inside(B, A[k]) || inside(A, B[k])) return true;
  return false;
}

}  // namespace

TEST(CarSeat, PartsAreNamedAndBoundToPanelMaterials) {
  const CarSeat& seat = coarse_seat();
  std::set<std::string> names, materials;
  for (const auto& p : seat.parts) {
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate part " << p.name;
    materials.insert(p.mesh.material);
    EXPECT_TRUE(p.mesh.has_name(p.name));
    EXPECT_TRUE(p.mesh.has_name("seat"));
  }
  EXPECT_EQ(materials,
            (std::set<std::string>{"centre", "bolster", "piping", "headrest", "post", "base"}));
  for (const char* n : {"cushion_centre", "cushion_bolster_left", "cushion_bolster_right",
                        "cushion_piping", "backrest_centre", "backrest_bolster_left",
                        "backrest_bolster_right", "backrest_piping", "headrest"})
    EXPECT_TRUE(names.count(n)) << n;
}

TEST(CarSeat, EveryPartIsClosedAndWoundOutwards) {
  for (const auto& part : coarse_seat().parts) {
    const TriangleMesh& m = part.mesh;
    size_t vertices = 0;
    const auto id = weld(m, &vertices);
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    double volume6 = 0;  // six times the signed volume (divergence theorem)
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      uint32_t v[3];
      for (int k = 0; k < 3; ++k) v[k] = id[m.indices[3 * t + k]];
      ASSERT_TRUE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) << part.name << " triangle " << t;
      for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
      const Vec3 p0 = m.position(m.indices[3 * t]), p1 = m.position(m.indices[3 * t + 1]),
                 p2 = m.position(m.indices[3 * t + 2]);
      volume6 += dot(p0, cross(p1, p2));
    }
    size_t bad = 0;
    for (const auto& [e, count] : directed) {
      const auto rev = directed.find({e.second, e.first});
      if (count != 1 || rev == directed.end() || rev->second != 1) ++bad;
    }
    EXPECT_EQ(bad, 0u) << part.name << ": edges not shared by exactly two faces, once each way";
    EXPECT_GT(volume6, 0) << part.name;
    const long euler = long(vertices) - long(directed.size() / 2) + long(m.triangle_count());
    EXPECT_EQ(euler, part.mesh.material == "piping" ? 0 : 2) << part.name;
  }
}

namespace {

// Pairs of triangles that share no vertex and intersect; 'pairs' counts the pairs tested.
size_t self_intersections(const TriangleMesh& m, size_t* pairs) {
  const auto id = weld(m);
  const size_t n = m.triangle_count();
  std::vector<Bounds3> box(n);
  std::vector<size_t> order(n);
  for (size_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) box[t].expand(m.position(m.indices[3 * t + k]));
    order[t] = t;
  }
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return box[a].lo.x < box[b].lo.x; });
  size_t hits = 0;
  *pairs = 0;
  for (size_t i = 0; i < n; ++i) {
    const size_t a = order[i];
    for (size_t j = i + 1; j < n && box[order[j]].lo.x <= box[a].hi.x; ++j) {
      const size_t b = order[j];
      if (box[b].lo.y > box[a].hi.y || box[b].hi.y < box[a].lo.y || box[b].lo.z > box[a].hi.z ||
          box[b].hi.z < box[a].lo.z)
        continue;
      bool adjacent = false;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l)
          adjacent = adjacent || id[m.indices[3 * a + k]] == id[m.indices[3 * b + l]];
      if (adjacent) continue;
      ++*pairs;
      Vec3 pa[3], pb[3];
      for (int k = 0; k < 3; ++k)
        pa[k] = m.position(m.indices[3 * a + k]), pb[k] = m.position(m.indices[3 * b + k]);
      bool hit = coplanar_overlap(pa, pb);
      for (int k = 0; k < 3 && !hit; ++k)
        hit = segment_hits_triangle(pa[k], pa[(k + 1) % 3], pb[0], pb[1], pb[2]) ||
              segment_hits_triangle(pb[k], pb[(k + 1) % 3], pa[0], pa[1], pa[2]);
      hits += hit;
    }
  }
  return hits;
}

}  // namespace

TEST(CarSeat, IntersectionCheckFindsCrossingAndOverlappingTriangles) {
  TriangleMesh m;
  // Triangle 0 in z = 0; triangle 1 pierces it; triangle 2 overlaps it in its plane; triangle 3
  // lies apart.
  m.positions = {0,    0,    0, 1,    0,    0, 0,    1,    0, 0.2f, 0.2f, -1,
                 0.3f, 0.2f, 1, 0.2f, 0.3f, 1, 0.1f, 0.1f, 0, 2,    0.1f, 0,
                 0.1f, 2,    0, 5,    5,    5, 6,    5,    5, 5,    6,    5};
  m.indices = {0, 1, 2, 3, 4, 5};
  size_t pairs = 0;
  EXPECT_EQ(self_intersections(m, &pairs), 1u);
  m.indices = {0, 1, 2, 6, 7, 8};
  EXPECT_EQ(self_intersections(m, &pairs), 1u);
  m.indices = {0, 1, 2, 9, 10, 11};
  EXPECT_EQ(self_intersections(m, &pairs), 0u);
}

TEST(CarSeat, NoPartIntersectsItself) {
  for (const auto& part : coarse_seat().parts) {
    size_t pairs = 0;
    EXPECT_EQ(self_intersections(part.mesh, &pairs), 0u) << part.name;
    EXPECT_GT(pairs, 0u) << part.name << ": the check tested nothing";
  }
}

TEST(CarSeat, TangentsAreOrthogonalToNormalsAndFollowTheWarp) {
  for (const auto& part : coarse_seat().parts) {
    size_t along = 0;
    weft::testing::expect_consistent_frames(part.mesh, [&](size_t v, const Vec3& t) {
      if (length(part.warp) == 0) return;  // piping: the warp follows the tube, tested below
      const TriangleMesh& m = part.mesh;
      const Vec3 n{m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]};
      // The faces across the warp carry another axis; at the box's corners their normals keep a
      // warp component of at least 1 / sqrt(3) = 0.58 before shaping, which tilts normals by
      // less than 20 degrees (the steepest slope is the backrest's wrap, 0.34): |n.warp| < 0.25
      // leaves only the faces along the warp. There the tangent is the warp axis bent by the
      // shaping, by less than 25 degrees (cos 0.9).
      if (std::abs(dot(n, part.warp)) > 0.25) return;
      const Vec3 w = normalize(part.warp - dot(part.warp, n) * n);
      EXPECT_GT(dot(t, w), 0.9) << part.name << " vertex " << v;
      ++along;
    });
    if (length(part.warp) > 0) {
      EXPECT_GT(along, part.mesh.vertex_count() / 4) << part.name;
    }
  }
  // Piping: the tangent runs along the tube, i.e. perpendicular to the ring's radius; the ring
  // around vertex v is the set of vertices with the same u, so neighbours along u differ in u.
  for (const auto& part : coarse_seat().parts) {
    if (part.mesh.material != "piping") continue;
    const TriangleMesh& m = part.mesh;
    for (size_t tri = 0; tri < m.triangle_count(); ++tri) {
      const uint32_t a = m.indices[3 * tri], b = m.indices[3 * tri + 1];
      const double du = m.uvs[2 * b] - m.uvs[2 * a], dv = m.uvs[2 * b + 1] - m.uvs[2 * a + 1];
      if (dv != 0 || du == 0) continue;  // an edge along the tube
      const Vec3 e = normalize(m.position(b) - m.position(a)) * (du > 0 ? 1 : -1);
      const Vec3 t{m.tangents[4 * a], m.tangents[4 * a + 1], m.tangents[4 * a + 2]};
      EXPECT_GT(dot(t, e), 0.9) << part.name << " triangle " << tri;
    }
  }
}

TEST(CarSeat, DefaultGridStaysWithinAFewHundredThousandTriangles) {
  const CarSeat seat = make_car_seat();
  size_t sum = 0;
  for (const auto& p : seat.parts) sum += p.mesh.triangle_count();
  EXPECT_EQ(seat.triangle_count(), sum);
  EXPECT_LE(seat.triangle_count(), 300000u);
  // Fine enough for the seams (about 12 mm wide) to show: more than 50k triangles.
  EXPECT_GT(seat.triangle_count(), 50000u);
}

TEST(CarSeat, IsDeterministic) {
  CarSeatOptions o;
  o.cell_mm = 20;
  const CarSeat a = make_car_seat(o), b = make_car_seat(o);
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (size_t i = 0; i < a.parts.size(); ++i) {
    EXPECT_EQ(a.parts[i].mesh.positions, b.parts[i].mesh.positions);
    EXPECT_EQ(a.parts[i].mesh.tangents, b.parts[i].mesh.tangents);
  }
}

TEST(CarSeat, BadOptionsNameTheField) {
  CarSeatOptions o;
  o.cell_mm = 0.1;
  try {
    make_car_seat(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cell_mm"), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_car_seat_gltf(fs::temp_directory_path() / "seat.obj", coarse_seat(), {}),
               Error);
}

TEST(CarSeat, GltfLoadsBackWithPartsMaterialsAndTangents) {
  const fs::path file = fs::temp_directory_path() / "weft-test-car-seat.glb";
  CarSeatOptions o;
  o.cell_mm = 12;
  write_car_seat_gltf(file, coarse_seat(), o);
  const nlohmann::json desc = {{"gltf", file.string()},
                               {"materials",
                                {{"centre", {{"type", "lambert"}}},
                                 {"bolster", {{"type", "lambert"}}},
                                 {"piping", {{"type", "lambert"}}},
                                 {"headrest", {{"type", "lambert"}}},
                                 {"post", {{"type", "lambert"}}},
                                 {"base", {{"type", "lambert"}}}}}};
  const SceneDescription d = parse_scene_description(desc, "/", "seat.json");
  ASSERT_EQ(d.meshes.size(), coarse_seat().parts.size());
  for (size_t i = 0; i < d.meshes.size(); ++i) {
    const auto& part = coarse_seat().parts[i];
    EXPECT_TRUE(d.meshes[i]->has_name(part.name));
    EXPECT_TRUE(d.meshes[i]->has_name("seat"));
    EXPECT_EQ(d.meshes[i]->material, part.mesh.material);
    EXPECT_EQ(d.meshes[i]->triangle_count(), part.mesh.triangle_count());
    // The loader renormalises tangents: equal to float rounding.
    ASSERT_EQ(d.meshes[i]->tangents.size(), part.mesh.tangents.size());
    for (size_t k = 0; k < part.mesh.tangents.size(); ++k)
      ASSERT_NEAR(d.meshes[i]->tangents[k], part.mesh.tangents[k], 1e-6) << part.name;
  }
  fs::remove(file);
}
