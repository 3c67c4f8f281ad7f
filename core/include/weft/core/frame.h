#pragma once
// Orthonormal frames. Local coordinates are (s, t, n) = (x, y, z), z along the normal.
// A fiber frame (the project's one convention, used by the fiber tables and docs/fiber-bsdf.md):
// normal n (outward from the cylinder), tangent t (fiber axis) and binormal b = n x t; in local
// coordinates t is x, b is y, n is z, so from_normal_tangent(n, t) builds it.
#include <cmath>

#include "weft/core/vec.h"

namespace weft {

struct Frame {
  Vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

  constexpr Frame() = default;
  constexpr Frame(const Vec3& s_, const Vec3& t_, const Vec3& n_) : s(s_), t(t_), n(n_) {}

  // Any frame around a unit normal (Duff et al. 2017, branchless, continuous except at n.z=-1).
  static Frame from_normal(const Vec3& n) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    return {Vec3{1 + sign * n.x * n.x * a, sign * b, -sign * n.x},
            Vec3{b, sign + n.y * n.y * a, -n.y}, n};
  }
  // Frame from a unit normal and a tangent hint (e.g. the fiber axis); the tangent is
  // Gram-Schmidt orthogonalised against n. Falls back to from_normal if the hint is parallel to n.
  static Frame from_normal_tangent(const Vec3& n, const Vec3& tangent) {
    Vec3 s = tangent - dot(tangent, n) * n;
    const double len2 = length_squared(s);
    if (!(len2 > 1e-20)) return from_normal(n);
    s = s / std::sqrt(len2);
    return {s, cross(n, s), n};
  }

  constexpr Vec3 to_local(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  constexpr Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

// Spherical helpers in a local frame (z up).
inline double cos_theta(const Vec3& w) {
  return w.z;
}
inline Vec3 spherical_direction(double theta, double phi) {
  const double st = std::sin(theta);
  return {st * std::cos(phi), st * std::sin(phi), std::cos(theta)};
}

}  // namespace weft
