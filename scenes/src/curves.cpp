#include "weft/scenes/curves.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {

Bounds3 FiberCurves::bounds() const {
  Bounds3 b;
  for (size_t i = 0; i < point_count(); ++i) {
    const Vec3 p = point(i);
    const double r = radius(i);
    b.expand(p - Vec3{r, r, r});
    b.expand(p + Vec3{r, r, r});
  }
  return b;
}

bool FiberCurves::has_name(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) != names.end();
}

void FiberCurves::validate(const std::string& file, const std::string& field) const {
  const std::string f = field.empty() ? "" : field + ".";
  if (points.size() % 4 != 0)
    throw Error(file, f + "points", "needs 4 numbers (x, y, z, radius) per point");
  const size_t n = curve_count();
  if (curve_points.size() != n || curve_yarn.size() != n)
    throw Error(file, f + "curve_points", "per-curve arrays differ in length");
  for (size_t c = 0; c < n; ++c) {
    const std::string cf = f + "curves[" + std::to_string(c) + "]";
    if (curve_points[c] < 2) throw Error(file, cf, "a fiber needs at least 2 points");
    if (size_t(curve_first[c]) + curve_points[c] > point_count())
      throw Error(file, cf, "its points run past the point array");
    if (curve_yarn[c] >= yarn_material.size())
      throw Error(file, cf, "its yarn index exceeds the yarn list");
  }
  for (size_t i = 0; i < point_count(); ++i) {
    const std::string pf = f + "points[" + std::to_string(i) + "]";
    if (!is_finite(point(i))) throw Error(file, pf, "non-finite position");
    if (!(std::isfinite(radius(i)) && radius(i) > 0))
      throw Error(file, pf, "radius must be finite and > 0");
  }
}

FiberSegmentIndex index_segments(const FiberCurves& curves) {
  FiberSegmentIndex s;
  s.first_point.reserve(curves.segment_count());
  s.curve.reserve(curves.segment_count());
  for (size_t c = 0; c < curves.curve_count(); ++c)
    for (uint32_t k = 0; k + 1 < curves.curve_points[c]; ++k) {
      s.first_point.push_back(curves.curve_first[c] + k);
      s.curve.push_back(static_cast<uint32_t>(c));
    }
  return s;
}

double FiberSegment::closest_u(const Vec3& p) const {
  const Vec3 a = p1 - p0;
  const double len2 = length_squared(a);
  if (!(len2 > 0)) return 0;
  return std::clamp(dot(p - p0, a) / len2, 0.0, 1.0);
}

std::optional<double> cylinder_exit_distance(const FiberSegment& seg, const Vec3& o,
                                             const Vec3& d) {
  const Vec3 a = seg.p1 - seg.p0;
  const double len = length(a);
  if (!(len > 0)) return std::nullopt;
  const Vec3 t = a / len;
  // Components perpendicular to the axis: |w + s v|^2 = r^2 with w = (o - p0)_perp, v = d_perp.
  const Vec3 w0 = o - seg.p0;
  const Vec3 w = w0 - t * dot(w0, t), v = d - t * dot(d, t);
  const double r = 0.5 * (seg.r0 + seg.r1);
  const double A = length_squared(v), B = dot(w, v), C = length_squared(w) - r * r;
  if (!(A > 1e-24)) return std::nullopt;
  const double disc = B * B - A * C;
  if (!(disc >= 0)) return std::nullopt;
  // The larger root, in the form that does not cancel (B and the root of the same sign).
  const double q = std::sqrt(disc);
  return B <= 0 ? (-B + q) / A : -C / (B + q);
}

double tube_corner_radius_scale(int sides) {
  return kPi / (sides * std::sin(kPi / sides));  // same mean width as the circle
}

FiberTubes make_fiber_tubes(const FiberCurves& curves, int sides) {
  if (sides < FiberGeometry::kMinTubeSides || sides > FiberGeometry::kMaxTubeSides)
    throw Error("", "tube_sides",
                "must lie in [" + std::to_string(FiberGeometry::kMinTubeSides) + ", " +
                    std::to_string(FiberGeometry::kMaxTubeSides) + "]");
  // Counted before anything is reserved: 3e7 curve points (the weave's limit) at 32 sides made
  // 2e9 triangles and died of std::bad_alloc. 5e7 is the weave's limit for yarn tubes too.
  const double triangles = 2.0 * sides * double(curves.segment_count());
  if (triangles > 5e7)
    throw Error("", "fiber_geometry.sides",
                "tubes of " + std::to_string(sides) + " sides around " +
                    std::to_string(curves.segment_count()) + " fiber segments make " +
                    ParamReader::fmt(triangles) +
                    " triangles (limit 5e7): use \"curves\", fewer sides or fewer fibers");
  FiberTubes out;
  TriangleMesh& m = out.mesh;
  m.names = curves.names;
  const size_t n = static_cast<size_t>(sides);
  m.positions.reserve(3 * n * curves.point_count());
  m.normals.reserve(3 * n * curves.point_count());
  m.tangents.reserve(4 * n * curves.point_count());
  m.indices.reserve(6 * n * curves.segment_count());
  const double stretch = tube_corner_radius_scale(sides);
  std::vector<double> cos_j(n), sin_j(n);
  for (size_t j = 0; j < n; ++j) {
    cos_j[j] = std::cos(2 * kPi * double(j) / sides);
    sin_j[j] = std::sin(2 * kPi * double(j) / sides);
  }
  uint32_t segment = 0;
  for (size_t c = 0; c < curves.curve_count(); ++c) {
    out.curve_first_triangle.push_back(static_cast<uint32_t>(m.triangle_count()));
    const size_t first = curves.curve_first[c], np = curves.curve_points[c];
    auto dir = [&](size_t k) {  // unit direction of segment k of this curve
      const Vec3 d = curves.point(first + k + 1) - curves.point(first + k);
      const double len = length(d);
      return len > 0 ? d / len : Vec3{1, 0, 0};
    };
    Vec3 u;  // the ring's reference direction, carried along the curve
    const uint32_t ring0 = static_cast<uint32_t>(m.vertex_count());
    for (size_t k = 0; k < np; ++k) {
      Vec3 t = k == 0 ? dir(0) : k + 1 == np ? dir(k - 1) : dir(k - 1) + dir(k);
      t = length(t) > 1e-12 ? normalize(t) : dir(k == 0 ? 0 : k - 1);
      if (k == 0) {
        u = Frame::from_normal(t).s;
      } else {
        u = u - t * dot(u, t);
        u = length(u) > 1e-12 ? normalize(u) : Frame::from_normal(t).s;
      }
      const Vec3 v = cross(t, u);
      const Vec3 p = curves.point(first + k);
      const double rho = curves.radius(first + k) * stretch;
      for (size_t j = 0; j < n; ++j) {
        const Vec3 radial = u * cos_j[j] + v * sin_j[j];
        const Vec3 q = p + radial * rho;
        m.positions.insert(m.positions.end(), {float(q.x), float(q.y), float(q.z)});
        m.normals.insert(m.normals.end(), {float(radial.x), float(radial.y), float(radial.z)});
        m.tangents.insert(m.tangents.end(), {float(t.x), float(t.y), float(t.z), 1.0f});
      }
    }
    for (size_t k = 0; k + 1 < np; ++k, ++segment) {
      const uint32_t a0 = ring0 + static_cast<uint32_t>(k * n), b0 = a0 + static_cast<uint32_t>(n);
      for (size_t j = 0; j < n; ++j) {
        const uint32_t j1 = static_cast<uint32_t>((j + 1) % n), jj = static_cast<uint32_t>(j);
        // Counter-clockwise seen from outside: (k, j), (k, j+1), (k+1, j+1) and (k+1, j).
        m.indices.insert(m.indices.end(), {a0 + jj, a0 + j1, b0 + j1});
        m.indices.insert(m.indices.end(), {a0 + jj, b0 + j1, b0 + jj});
        out.triangle_segment.push_back(segment);
        out.triangle_segment.push_back(segment);
      }
    }
  }
  return out;
}

}  // namespace weft
