#include "preview_geometry.h"

#include <cmath>
#include <map>
#include <tuple>

#include "weft/core/math.h"
#include "weft/core/vec.h"

namespace weft::gltf_detail {
namespace {

double signed_pow(double x, double e) {
  return std::copysign(std::pow(std::abs(x), e), x);
}

void push(std::vector<float>& v, const Vec3& p) {
  v.insert(v.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
}

// Triangles of a (nu + 1) x (nv + 1) vertex grid, row-major in v.
void grid_indices(GltfMesh& m, int nu, int nv) {
  const auto at = [nu](int i, int j) { return static_cast<uint32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      m.indices.insert(m.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j),
                                         at(i + 1, j + 1), at(i + 1, j)});
}

// The drape's point for sheet coordinates (x, z), the sheet's centre on the sphere's top.
Vec3 drape_point(double x, double z, double radius_m, double top_m, double contact_rad) {
  const double s = std::hypot(x, z);  // arc length from the top, along the sheet
  if (s < 1e-9) return {0, top_m, 0};
  const double dx = x / s, dz = z / s;
  const double centre_y = top_m - radius_m;
  const double a = std::min(s / radius_m, contact_rad);
  double r = radius_m * std::sin(a), y = centre_y + radius_m * std::cos(a);
  const double hanging_m = s - radius_m * a;
  if (hanging_m > 0) {
    // Along the tangent at the contact, plus folds: a radial wave around the sphere that grows
    // with the length hanging, as a tablecloth's skirt gathers.
    r += hanging_m * std::cos(contact_rad);
    y -= hanging_m * std::sin(contact_rad);
    const double phi = std::atan2(z, x);
    r += 0.12 * hanging_m * std::sin(9 * phi);
  }
  return {r * dx, y, r * dz};
}

}  // namespace

void smooth_normals(GltfMesh& m) {
  using Key = std::tuple<long, long, long>;
  const auto key = [&m](size_t v) {
    const auto q = [](float x) { return std::lround(static_cast<double>(x) * 1e5); };
    return Key{q(m.positions_m[3 * v]), q(m.positions_m[3 * v + 1]), q(m.positions_m[3 * v + 2])};
  };
  const auto pos = [&m](size_t v) {
    return Vec3{m.positions_m[3 * v], m.positions_m[3 * v + 1], m.positions_m[3 * v + 2]};
  };
  std::map<Key, Vec3> sum;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const size_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
    const Vec3 n = cross(pos(b) - pos(a), pos(c) - pos(a));  // length: twice the area
    for (size_t v : {a, b, c}) sum[key(v)] += n;
  }
  m.normals.clear();
  for (size_t v = 0; v < m.vertices(); ++v) {
    const Vec3 n = sum[key(v)];
    push(m.normals, length(n) > 0 ? normalize(n) : Vec3{0, 1, 0});
  }
}

GltfMesh cushion_mesh(double width_m, double thickness_m, int segments) {
  GltfMesh m;
  m.name = "cushion";
  const int nu = 2 * segments, nv = segments;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      // phi turns clockwise seen from above so that the triangles face outwards.
      const double theta = kPi * j / nv, phi = -2 * kPi * i / nu;
      // A superellipsoid: boxy across (exponent 0.3), round over its top and bottom.
      const double x = 0.5 * width_m * signed_pow(std::sin(theta) * std::cos(phi), 0.3);
      const double z = 0.5 * width_m * signed_pow(std::sin(theta) * std::sin(phi), 0.3);
      const double ux = 2 * x / width_m, uz = 2 * z / width_m;
      // Puffed: full thickness in the middle, a third of it at the seam around the edge.
      const double puff = 1.0 / 3 + (2.0 / 3) * (1 - std::pow(ux, 4)) * (1 - std::pow(uz, 4));
      const double y = 0.5 * thickness_m * puff * signed_pow(std::cos(theta), 0.8);
      push(m.positions_m, {x, y, z});
      m.uvs.insert(m.uvs.end(), {static_cast<float>(i) / nu, static_cast<float>(j) / nv});
    }
  grid_indices(m, nu, nv);
  smooth_normals(m);
  m.translation_m = {0, 0.5 * thickness_m, 0};
  return m;
}

GltfMesh drape_mesh(double side_m, double radius_m, double top_m, double contact_rad,
                    int segments) {
  GltfMesh m;
  m.name = "draped_cloth";
  for (int j = 0; j <= segments; ++j)
    for (int i = 0; i <= segments; ++i) {
      const double u = static_cast<double>(i) / segments, v = static_cast<double>(j) / segments;
      push(m.positions_m,
           drape_point((u - 0.5) * side_m, (v - 0.5) * side_m, radius_m, top_m, contact_rad));
      m.uvs.insert(m.uvs.end(), {static_cast<float>(u), static_cast<float>(v)});
    }
  grid_indices(m, segments, segments);
  smooth_normals(m);
  return m;
}

}  // namespace weft::gltf_detail
