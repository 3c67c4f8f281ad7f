#pragma once
// 3-vectors in double precision: the physics (Mie, photon transport) needs it and the renderer
// loses nothing measurable by using the same type.
#include <cmath>
#include <ostream>

#include "weft/core/componentwise.h"

namespace weft {

struct Vec3 {
  double x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}

  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  constexpr Vec3& operator-=(const Vec3& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  constexpr Vec3& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr bool operator==(const Vec3&) const = default;
};

// a + b, a - b, v * s, s * v and v / s (componentwise.h).
template <>
inline constexpr bool kComponentWise<Vec3> = true;

constexpr Vec3 mul(const Vec3& a, const Vec3& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
constexpr double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double length_squared(const Vec3& a) {
  return dot(a, a);
}
inline double length(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalize(const Vec3& a) {
  return a / length(a);
}
inline bool is_finite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
// Mirror d about the unit normal n (both pointing away from the surface).
constexpr Vec3 reflect(const Vec3& d, const Vec3& n) {
  return 2.0 * dot(d, n) * n - d;
}

inline std::ostream& operator<<(std::ostream& os, const Vec3& v) {
  return os << '(' << v.x << ", " << v.y << ", " << v.z << ')';
}

struct Vec2 {
  double x = 0, y = 0;
};

}  // namespace weft
