#include "weft/scenes/mesh.h"

#include <algorithm>
#include <cmath>

#include "weft/core/frame.h"

namespace weft {

Bounds3 TriangleMesh::bounds() const {
  Bounds3 b;
  for (size_t v = 0; v < vertex_count(); ++v) b.expand(position(v));
  return b;
}

bool TriangleMesh::has_name(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) != names.end();
}

void derive_tangents(TriangleMesh& mesh) {
  if (!mesh.tangents.empty()) return;
  const size_t nv = mesh.vertex_count();
  std::vector<Vec3> normal(nv), dpdu(nv);
  const bool has_normals = mesh.normals.size() == 3 * nv;
  const bool has_uvs = mesh.uvs.size() == 2 * nv;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1],
                   i2 = mesh.indices[3 * t + 2];
    const Vec3 p0 = mesh.position(i0), e1 = mesh.position(i1) - p0, e2 = mesh.position(i2) - p0;
    const Vec3 face = cross(e1, e2);  // length = 2 x area: area-weighted accumulation
    if (!has_normals)
      for (uint32_t i : {i0, i1, i2}) normal[i] += face;
    if (!has_uvs) continue;
    // Solve e1 = du1 dpdu + dv1 dpdv, e2 = du2 dpdu + dv2 dpdv for dpdu (pbrt's derivation).
    const double du1 = mesh.uvs[2 * i1] - mesh.uvs[2 * i0],
                 dv1 = mesh.uvs[2 * i1 + 1] - mesh.uvs[2 * i0 + 1];
    const double du2 = mesh.uvs[2 * i2] - mesh.uvs[2 * i0],
                 dv2 = mesh.uvs[2 * i2 + 1] - mesh.uvs[2 * i0 + 1];
    const double det = du1 * dv2 - du2 * dv1;
    if (!(std::abs(det) > 1e-30)) continue;
    Vec3 d = (dv2 * e1 - dv1 * e2) / det;
    const double len = length(d);
    if (!(len > 0) || !std::isfinite(len)) continue;
    d = d * (length(face) / len);  // unit direction weighted by twice the area
    for (uint32_t i : {i0, i1, i2}) dpdu[i] += d;
  }
  mesh.tangents.resize(4 * nv);
  for (size_t v = 0; v < nv; ++v) {
    Vec3 n = has_normals
                 ? Vec3{mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]}
                 : normal[v];
    const double nlen = length(n);
    n = nlen > 0 ? n / nlen : Vec3{0, 0, 1};
    const Frame f = Frame::from_normal_tangent(n, dpdu[v]);  // arbitrary frame if dpdu ~ 0
    mesh.tangents[4 * v] = static_cast<float>(f.s.x);
    mesh.tangents[4 * v + 1] = static_cast<float>(f.s.y);
    mesh.tangents[4 * v + 2] = static_cast<float>(f.s.z);
    mesh.tangents[4 * v + 3] = 1.0f;
  }
}

}  // namespace weft
