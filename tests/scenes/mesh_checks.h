#pragma once
// Checks shared by the tests of generated yarn tubes (the legacy patch and the woven sample).
#include <gtest/gtest.h>

#include <functional>

#include "weft/scenes/mesh.h"

namespace weft::testing {

// Every vertex: a unit normal perpendicular to its tangent, then the caller's checks of that
// vertex ('per_vertex', given its index and tangent). Every triangle: wound so that its geometric
// normal agrees with its first vertex's normal, which is outward on a tube.
inline void expect_consistent_frames(
    const TriangleMesh& m, const std::function<void(size_t v, const Vec3& tangent)>& per_vertex) {
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const Vec3 n{m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]};
    const Vec3 t{m.tangents[4 * v], m.tangents[4 * v + 1], m.tangents[4 * v + 2]};
    EXPECT_NEAR(length(n), 1, 1e-6);
    EXPECT_NEAR(dot(n, t), 0, 1e-6);
    per_vertex(v, t);
  }
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t i0 = m.indices[3 * t];
    const Vec3 p0 = m.position(i0);
    const Vec3 ng =
        cross(m.position(m.indices[3 * t + 1]) - p0, m.position(m.indices[3 * t + 2]) - p0);
    EXPECT_GT(dot(ng, Vec3{m.normals[3 * i0], m.normals[3 * i0 + 1], m.normals[3 * i0 + 2]}), 0);
  }
}

}  // namespace weft::testing
