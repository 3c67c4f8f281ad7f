#include "weft/materials/cook_torrance.h"

#include <cmath>
#include <optional>

#include "weft/materials/fresnel.h"

namespace weft {
namespace {

// Both directions moved to the upper side when wo is below (the back side mirrors the front).
struct Upper {
  Vec3 wo, wi;
  bool flipped;
};
Upper to_upper(const Vec3& wo, const Vec3& wi) {
  if (wo.z >= 0) return {wo, wi, false};
  return {{wo.x, wo.y, -wo.z}, {wi.x, wi.y, -wi.z}, true};
}

// The half vector of a reflection above the surface; none when either direction is not above it
// or they are opposite.
std::optional<Vec3> upper_half_vector(const Vec3& wo, const Vec3& wi) {
  if (wo.z <= 0 || wi.z <= 0) return std::nullopt;
  const Vec3 sum = wo + wi;
  const double len2 = length_squared(sum);
  if (len2 == 0) return std::nullopt;
  return sum / std::sqrt(len2);
}

}  // namespace

double CookTorranceBsdf::eval_upper(const Vec3& wo, const Vec3& wi) const {
  const auto h = upper_half_vector(wo, wi);
  if (!h) return 0;
  const double f = fresnel_dielectric(dot(wo, *h), 1.0, ior);
  return f * distribution.d(*h) * distribution.g2(wo, wi) / (4 * wo.z * wi.z);
}

double CookTorranceBsdf::pdf_upper(const Vec3& wo, const Vec3& wi) const {
  const auto h = upper_half_vector(wo, wi);
  if (!h) return 0;
  const double wo_h = dot(wo, *h);
  if (wo_h <= 0) return 0;
  // Jacobian of the reflection h -> wi: dw_h / dw_i = 1 / (4 wo.h).
  return distribution.pdf_normal(wo, *h) / (4 * wo_h);
}

Rgb CookTorranceBsdf::eval(const Vec3& wo, const Vec3& wi) const {
  const Upper up = to_upper(wo, wi);
  return tint * eval_upper(up.wo, up.wi);
}

double CookTorranceBsdf::pdf(const Vec3& wo, const Vec3& wi) const {
  const Upper up = to_upper(wo, wi);
  return pdf_upper(up.wo, up.wi);
}

std::optional<BsdfSample> CookTorranceBsdf::sample(const Vec3& wo, Vec2 u, double) const {
  if (wo.z == 0) return std::nullopt;
  const Upper up = to_upper(wo, Vec3{});
  const Vec3 h = distribution.sample_normal(up.wo, u);
  const double wo_h = dot(up.wo, h);
  if (wo_h <= 0) return std::nullopt;
  Vec3 wi = normalize(reflect(up.wo, h));
  if (wi.z <= 0) return std::nullopt;  // reflected below the surface: the sample is lost
  const double pdf = pdf_upper(up.wo, wi);
  if (!(pdf > 0)) return std::nullopt;
  const double f = eval_upper(up.wo, wi);
  if (up.flipped) wi.z = -wi.z;
  return BsdfSample{wi, tint * (f * std::abs(wi.z) / pdf), pdf, false};
}

}  // namespace weft
