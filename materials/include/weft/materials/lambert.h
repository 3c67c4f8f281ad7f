#pragma once
// Ideal diffuse reflection.
#include <optional>

#include "weft/materials/bsdf.h"

namespace weft {

// Ideal diffuse reflector of albedo 'reflectance' on the side wo lies on (two-sided).
struct LambertBsdf {
  Rgb reflectance{0.5};

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
};

}  // namespace weft
