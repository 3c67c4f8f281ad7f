#pragma once
// Fibers as round curves, plain data in world space (metres, glTF's unit, +y up): polylines with
// a radius per point, the form Embree's round curves take. Written by the weave generator
// (weave.h); how they are stored in glTF is described there. Read back from glTF by gltf.h (one
// FiberCurves per glTF mesh instance), rendered by render_scene.h as round curves or as tubes.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/vec.h"
#include "weft/scenes/mesh.h"

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

  // Box of the fibers' surfaces (every point grown by its radius).
  Bounds3 bounds() const;
  bool has_name(const std::string& name) const;
  // Throws weft::Error(file, field, ...) unless the curves are well formed: sizes agree, every
  // curve has >= 2 points inside 'points', every coordinate is finite, every radius finite and
  // > 0, every curve_yarn indexes yarn_material.
  void validate(const std::string& file, const std::string& field) const;
};

// Segments are numbered curve by curve, in curve order: segment k of curve c joins its points k
// and k + 1. These are the primitives of the Embree curve geometry (render_scene.h).
struct FiberSegmentIndex {
  std::vector<uint32_t> first_point;  // per segment: its first point (the second is next)
  std::vector<uint32_t> curve;        // per segment: its curve
};
FiberSegmentIndex index_segments(const FiberCurves& curves);

// One straight piece of a fiber: the axis from p0 to p1, radii r0 and r1 at its ends (Embree's
// round linear curve: a cone, a cylinder when r0 == r1, with spheres at the fiber's ends).
struct FiberSegment {
  Vec3 p0, p1;
  double r0 = 0, r1 = 0;

  // Unit axis direction p0 -> p1 (the fiber frame's tangent, x).
  Vec3 tangent() const { return normalize(p1 - p0); }
  // Parameter u in [0, 1] of the axis point closest to p (clamped to the segment).
  double closest_u(const Vec3& p) const;
  Vec3 axis_point(double u) const { return p0 + (p1 - p0) * u; }
  double radius_at(double u) const { return r0 + (r1 - r0) * u; }
};

// Where the straight line o + t d (d unit) leaves the fiber's cylinder: the larger root t of
// |(o + t d - p0) x a| = r for the segment's infinite axis line a and its mean radius r (exact for
// the cylinders fibers are). nullopt when the line misses the cylinder or runs along the axis.
// The fabric estimator uses it to find where light that enters a fiber at one point leaves it.
std::optional<double> cylinder_exit_distance(const FiberSegment& segment, const Vec3& o,
                                             const Vec3& d);

// How a renderer represents fibers: Embree round linear curves (exact cylinders, the default), or
// closed-around tubes of triangles (a polygon of 'tube_sides' sides around each segment).
struct FiberGeometry {
  enum class Type { curves, tubes };
  Type type = Type::curves;
  int tube_sides = 8;
  static constexpr int kMinTubeSides = 3, kMaxTubeSides = 64;
};

// Fibers as triangle tubes: around each point a ring of 'sides' vertices in the plane normal to
// the mean of its segments' directions (rings turned along the fiber by parallel transport, so
// tubes do not twist), joined ring to ring; open at the fibers' ends (as the weave generator's
// yarn tubes). The ring's circumradius is r * pi / (sides * sin(pi / sides)), which gives the
// polygon the circle's mean projected width (Cauchy's formula: mean width = perimeter / pi), so
// that a tube intercepts on average as much light as the round fiber. Vertex normals are radial
// and tangents point along the fiber (w = +1): the fiber frame. Triangles are counter-clockwise
// seen from outside.
struct FiberTubes {
  TriangleMesh mesh;
  std::vector<uint32_t> triangle_segment;      // per triangle: its segment (index_segments order)
  std::vector<uint32_t> curve_first_triangle;  // per curve: its first triangle (contiguous)
};
FiberTubes make_fiber_tubes(const FiberCurves& curves, int sides);
// The tubes' polygon of 'sides' sides has the circle's mean width: its corners lie at this
// multiple of the fiber's radius.
double tube_corner_radius_scale(int sides);

}  // namespace weft
