#pragma once
// Small numeric helpers shared by every library. Radians inside the code, degrees only at the UI.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace weft {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kInvPi = 1.0 / std::numbers::pi;
inline constexpr double kInv4Pi = 0.25 / std::numbers::pi;

constexpr double deg_to_rad(double deg) {
  return deg * (kPi / 180.0);
}
constexpr double rad_to_deg(double rad) {
  return rad * (180.0 / kPi);
}
constexpr double sqr(double x) {
  return x * x;
}
// sqrt that tolerates tiny negative round-off (e.g. 1 - cos^2).
inline double safe_sqrt(double x) {
  return std::sqrt(std::max(0.0, x));
}
inline double safe_acos(double x) {
  return std::acos(std::clamp(x, -1.0, 1.0));
}

}  // namespace weft
