#include "weft/core/sphere_mapping.h"

#include <algorithm>
#include <cmath>

#include "weft/core/math.h"

namespace weft {

Vec3 equal_area_square_to_sphere(Vec2 p) {
  // To [-1,1]^2; the octahedron's upper half is the diamond |u| + |v| <= 1.
  const double u = 2 * p.x - 1, v = 2 * p.y - 1;
  const double up = std::abs(u), vp = std::abs(v);
  const double signed_distance = 1 - (up + vp);
  const double r = 1 - std::abs(signed_distance);
  const double phi = (r == 0 ? 1 : (vp - up) / r + 1) * (kPi / 4);
  const double z = std::copysign(1 - r * r, signed_distance);
  const double k = r * safe_sqrt(2 - r * r);
  return {std::copysign(std::cos(phi), u) * k, std::copysign(std::sin(phi), v) * k, z};
}

Vec2 equal_area_sphere_to_square(const Vec3& d) {
  const double x = std::abs(d.x), y = std::abs(d.y), z = std::abs(d.z);
  const double r = safe_sqrt(1 - z);
  const double phi = std::atan2(y, x);  // in [0, pi/2]
  double v = phi * (2 / kPi) * r;
  double u = r - v;
  if (d.z < 0) {
    const double u0 = u;
    u = 1 - v;
    v = 1 - u0;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {std::clamp(0.5 * (u + 1), 0.0, 1.0), std::clamp(0.5 * (v + 1), 0.0, 1.0)};
}

}  // namespace weft
