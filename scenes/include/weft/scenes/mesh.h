#pragma once
// Triangle meshes as plain data, already in world space (metres, glTF's unit). Shared read-only
// between a SceneDescription and the RenderScenes built from it.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/vec.h"

namespace weft {

struct Bounds3 {
  Vec3 lo{1e300, 1e300, 1e300};
  Vec3 hi{-1e300, -1e300, -1e300};

  bool empty() const { return lo.x > hi.x; }
  void expand(const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  void expand(const Bounds3& b) {
    if (!b.empty()) expand(b.lo), expand(b.hi);
  }
  Vec3 center() const { return 0.5 * (lo + hi); }
  Vec3 corner(int i) const {
    return {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
  }
};

struct TriangleMesh {
  // Binding key of the material: the glTF material name ("material_<index>" when unnamed), or ""
  // when the primitive has none. The scene description maps it to a Weft material.
  std::string material;
  // Names that select this mesh as an object (masks, framing, gonioreflectometer sample): its own
  // node name, every ancestor's node name and its glTF mesh name (inline objects: their name).
  std::vector<std::string> names;

  std::vector<float> positions;   // xyz per vertex
  std::vector<float> normals;     // xyz per vertex (unit), or empty: flat shading
  std::vector<float> tangents;    // xyzw per vertex (glTF convention), or empty before derivation
  std::vector<float> uvs;         // uv per vertex, or empty
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise seen from the front

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
  Vec3 position(size_t v) const {
    return {positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
  }
  Bounds3 bounds() const;
  bool has_name(const std::string& name) const;
};

// Fills mesh.tangents when empty: from the UVs (per-triangle dP/du, area-weighted, averaged per
// vertex, orthogonalised against the normal), or an arbitrary frame around the normal where there
// are no UVs or dP/du degenerates. Needs normals or falls back to face normals.
void derive_tangents(TriangleMesh& mesh);

}  // namespace weft
