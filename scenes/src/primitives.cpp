#include "weft/scenes/primitives.h"

#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "weft/core/frame.h"

namespace weft {

namespace {
void push(std::vector<float>& v, const Vec3& p) {
  v.push_back(static_cast<float>(p.x));
  v.push_back(static_cast<float>(p.y));
  v.push_back(static_cast<float>(p.z));
}
}  // namespace

TriangleMesh make_quad(const Vec3& center, const Vec3& normal, const Vec3& tangent, double w,
                       double h) {
  const Frame f = Frame::from_normal_tangent(normalize(normal), tangent);
  TriangleMesh m;
  const double u[4] = {0, 1, 1, 0}, v[4] = {0, 0, 1, 1};
  for (int i = 0; i < 4; ++i) {
    push(m.positions, center + f.s * ((u[i] - 0.5) * w) + f.t * ((v[i] - 0.5) * h));
    push(m.normals, f.n);
    push(m.tangents, f.s);
    m.tangents.push_back(1.0f);
    m.uvs.push_back(static_cast<float>(u[i]));
    m.uvs.push_back(static_cast<float>(v[i]));
  }
  // s x t = n, so (0, 1, 2) is counter-clockwise seen from the normal's side.
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

TriangleMesh make_sphere(const Vec3& center, double radius, int subdivisions, bool inward) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> verts = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                             {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                             {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& v : verts) v = normalize(v);
  std::vector<std::array<uint32_t, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      verts.push_back(normalize(verts[a] + verts[b]));
      const auto id = static_cast<uint32_t>(verts.size() - 1);
      mid[key] = id;
      return id;
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& f : faces) {
      const uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    faces = std::move(next);
  }
  TriangleMesh m;
  for (const auto& v : verts) {
    push(m.positions, center + v * radius);
    push(m.normals, inward ? -v : v);
  }
  for (const auto& f : faces) {
    // The icosahedron table is counter-clockwise seen from outside.
    if (inward)
      m.indices.insert(m.indices.end(), {f[0], f[2], f[1]});
    else
      m.indices.insert(m.indices.end(), {f[0], f[1], f[2]});
  }
  derive_tangents(m);
  return m;
}

}  // namespace weft
