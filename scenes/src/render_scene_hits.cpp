// The surface at a RenderScene hit: a triangle's point, normals, shading frame, shadow-terminator
// lift and offset, and a round fiber's, in double precision from Embree's single-precision hit.
#include "render_scene_hits.h"

#include <algorithm>
#include <cmath>

namespace weft {

namespace {

// Vertex i of 'm', moved by 'shift' (null: not moved) as a shifted copy of the mesh holds it:
// float sums, the bits of a copy whose positions were shifted in place.
Vec3 vertex(const TriangleMesh& m, uint32_t i, const Vec3* shift) {
  if (!shift) return m.position(i);
  const float* p = &m.positions[3 * size_t(i)];
  return {p[0] + static_cast<float>(shift->x), p[1] + static_cast<float>(shift->y),
          p[2] + static_cast<float>(shift->z)};
}

}  // namespace

// The mesh's vertex normals made unit in double precision (zero where a normal is degenerate),
// once per scene: every hit's shadow-terminator lift reads three of them.
std::vector<Vec3> unit_vertex_normals(const TriangleMesh& m,
                                      const std::function<bool()>& keep_going) {
  std::vector<Vec3> out(m.normals.size() / 3);
  for (size_t v = 0; v < out.size(); ++v) {
    if (keep_going && v % kUnitNormalsPerPoll == 0 && !keep_going()) return out;
    const Vec3 nk{m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]};
    const double nlen = length(nk);
    if (nlen > 1e-12) out[v] = nk / nlen;
  }
  return out;
}

// Fills the hit on triangle 'prim' of 'm' (whose unit_vertex_normals are 'unit_normals'), moved
// by 'shift' (null: in place), at barycentrics (b1, b2).
void triangle_hit(const TriangleMesh& m, const std::vector<Vec3>& unit_normals, uint32_t prim,
                  double b1, double b2, const Ray& ray, SurfaceHit* hit, const Vec3* shift) {
  const uint32_t i0 = m.indices[3 * prim], i1 = m.indices[3 * prim + 1],
                 i2 = m.indices[3 * prim + 2];
  const double b0 = 1 - b1 - b2;
  const Vec3 p0 = vertex(m, i0, shift), p1 = vertex(m, i1, shift), p2 = vertex(m, i2, shift);
  hit->p = b0 * p0 + b1 * p1 + b2 * p2;
  Vec3 ng = cross(p1 - p0, p2 - p0);
  const double ng_len = length(ng);
  ng = ng_len > 0 ? ng / ng_len : -ray.d;
  hit->ng = ng;
  hit->prim = prim;
  auto attr3 = [&](const std::vector<float>& a, int stride) {
    return b0 * Vec3{a[stride * i0], a[stride * i0 + 1], a[stride * i0 + 2]} +
           b1 * Vec3{a[stride * i1], a[stride * i1 + 1], a[stride * i1 + 2]} +
           b2 * Vec3{a[stride * i2], a[stride * i2 + 1], a[stride * i2 + 2]};
  };
  Vec3 ns = ng;
  hit->lift_front = hit->lift_back = Vec3{};
  if (!m.normals.empty()) {
    const Vec3 n = attr3(m.normals, 3);
    const double len = length(n);
    if (len > 1e-12) ns = n / len;
    // Shadow-terminator lift (SurfaceHit::lift_front): the corners' tangent planes, each side.
    const uint32_t corner[3] = {i0, i1, i2};
    const Vec3 pc[3] = {p0, p1, p2};
    const double bc[3] = {b0, b1, b2};
    for (int k = 0; k < 3; ++k) {
      const Vec3& nu = unit_normals[corner[k]];
      if (nu == Vec3{}) continue;
      const double d = dot(hit->p - pc[k], nu);
      hit->lift_front -= nu * (bc[k] * std::min(0.0, d));
      hit->lift_back -= nu * (bc[k] * std::max(0.0, d));
    }
  }
  const Vec3 tangent = m.tangents.empty() ? Vec3{} : attr3(m.tangents, 4);
  hit->shading = Frame::from_normal_tangent(ns, tangent);
  if (!m.uvs.empty()) {
    hit->uv = {b0 * m.uvs[2 * i0] + b1 * m.uvs[2 * i1] + b2 * m.uvs[2 * i2],
               b0 * m.uvs[2 * i0 + 1] + b1 * m.uvs[2 * i1 + 1] + b2 * m.uvs[2 * i2 + 1]};
  } else {
    hit->uv = {b1, b2};
  }
  // Float intersection error grows with the coordinates' magnitude: offset relative to it.
  double mag = 0;
  for (const Vec3& p : {p0, p1, p2})
    mag = std::max({mag, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  hit->offset = 2e-6 * mag + 1e-30;  // ~30 float ulps of the largest coordinate
}

// Fills the hit on a round curve segment from Embree's distance: the point is put back onto the
// fiber's surface (radially from the axis point closest to the ray's point), in double precision.
void curve_hit(const FiberSegment& s, double t, const Ray& ray, SurfaceHit* hit) {
  const Vec3 q = ray.o + ray.d * t;
  const double u = s.closest_u(q);
  const Vec3 c = s.axis_point(u);
  const Vec3 axis = s.p1 - s.p0;
  const double axis_len = length(axis);
  Vec3 n = q - c;
  double len = length(n);
  if (!(len > 0)) {  // on the axis (never for a hit from outside): face the ray
    n = -ray.d - (axis_len > 0 ? axis * (dot(-ray.d, axis) / (axis_len * axis_len)) : Vec3{});
    len = length(n);
    n = len > 0 ? n / len : -ray.d;
  } else {
    n = n / len;
  }
  hit->p = c + n * s.radius_at(u);
  hit->ng = n;
  // The fiber frame: tangent along the segment (orthogonalised against n on the end spheres).
  hit->shading = Frame::from_normal_tangent(n, axis_len > 0 ? axis / axis_len : Vec3{});
  hit->uv = {u, 0};
  hit->lift_front = hit->lift_back = Vec3{};  // a fiber has no smooth surface to lift onto
  const Vec3& p = hit->p;
  const double mag = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  hit->offset = 2e-6 * mag + 1e-30;
}

}  // namespace weft
