#include "weft/materials/lambert.h"

#include <cmath>

#include "weft/core/math.h"

namespace weft {

Vec3 sample_cosine_hemisphere(Vec2 u) {
  // Uniform disk by the polar map, lifted to the hemisphere (Malley's method).
  const double r = std::sqrt(u.x);
  const double phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), safe_sqrt(1 - u.x)};
}

Rgb LambertBsdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (wo.z * wi.z <= 0) return Rgb(0.0);
  return reflectance * kInvPi;
}

std::optional<BsdfSample> LambertBsdf::sample(const Vec3& wo, Vec2 u, double) const {
  if (wo.z == 0) return std::nullopt;
  Vec3 wi = sample_cosine_hemisphere(u);
  if (wi.z <= 0) return std::nullopt;
  if (wo.z < 0) wi.z = -wi.z;
  return BsdfSample{wi, reflectance, std::abs(wi.z) * kInvPi, false};
}

double LambertBsdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (wo.z * wi.z <= 0) return 0;
  return std::abs(wi.z) * kInvPi;
}

}  // namespace weft
