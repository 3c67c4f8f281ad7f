#include "weft/materials/cook_torrance.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "weft/core/math.h"
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

SurfaceAlbedoTable::SurfaceAlbedoTable(MicrofacetModel model, double alpha, double ior, int nodes,
                                       int samples_per_side) {
  const CookTorranceBsdf ct{{model, alpha}, ior, Rgb(1.0)};
  albedo_.resize(nodes);
  for (int k = 0; k < nodes; ++k) {
    // Nodes uniform in sqrt(cos theta): dense at grazing angles, where a smooth lobe's albedo
    // changes fastest (uniform cos nodes left 1.5 % errors there at alpha = 0.01).
    const double u = static_cast<double>(k) / (nodes - 1);
    const double cos_t = std::max(1e-6, u * u);
    const Vec3 w{safe_sqrt(1 - cos_t * cos_t), 0, cos_t};
    double sum = 0;
    for (int a = 0; a < samples_per_side; ++a)
      for (int b = 0; b < samples_per_side; ++b) {
        const Vec2 u{(a + 0.5) / samples_per_side, (b + 0.5) / samples_per_side};
        if (const auto s = ct.sample(w, u, 0.5)) sum += s->weight.r;
      }
    albedo_[k] = sum / (samples_per_side * samples_per_side);
  }
}

double SurfaceAlbedoTable::operator()(double cos_theta) const {
  const double x = std::sqrt(std::clamp(cos_theta, 0.0, 1.0)) * (albedo_.size() - 1);
  const size_t i = std::min(static_cast<size_t>(x), albedo_.size() - 2);
  const double t = x - i;
  return (1 - t) * albedo_[i] + t * albedo_[i + 1];
}

}  // namespace weft
