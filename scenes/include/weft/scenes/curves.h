#pragma once
// Fibers as round curves, plain data in world space (metres, glTF's unit, +y up): polylines with
// a radius per point, the form Embree's round curves take. Written by the weave generator
// (weave.h); how they are stored in glTF is described there.
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/vec.h"

namespace weft {

struct FiberCurves {
  std::vector<float> points;               // x, y, z, radius per point (metres)
  std::vector<uint32_t> curve_first;       // per curve: index of its first point
  std::vector<uint32_t> curve_points;      // per curve: number of points (>= 2)
  std::vector<uint32_t> curve_yarn;        // per curve: index into yarn_material
  std::vector<std::string> yarn_material;  // per yarn: the material key, "warp" or "weft"
  // Names that select these curves as an object (as TriangleMesh::names), e.g. "patch".
  std::vector<std::string> names;

  size_t curve_count() const { return curve_first.size(); }
  size_t point_count() const { return points.size() / 4; }
  // Polyline segments: points - curves.
  size_t segment_count() const {
    size_t n = 0;
    for (uint32_t c : curve_points) n += c - 1;
    return n;
  }
  Vec3 point(size_t i) const { return {points[4 * i], points[4 * i + 1], points[4 * i + 2]}; }
  double radius(size_t i) const { return points[4 * i + 3]; }
  const std::string& material(size_t curve) const { return yarn_material[curve_yarn[curve]]; }
};

}  // namespace weft
