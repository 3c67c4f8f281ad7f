#include "weft/materials/microfacet.h"

#include <cmath>
#include <limits>

#include "weft/core/math.h"

namespace weft {

const char* microfacet_model_name(MicrofacetModel model) {
  return model == MicrofacetModel::kBeckmann ? "beckmann" : "ggx";
}

double MicrofacetDistribution::d(const Vec3& h) const {
  const double c2 = h.z * h.z;
  if (h.z <= 0) return 0;
  const double a2 = alpha * alpha;
  if (model == MicrofacetModel::kGgx) {
    // alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2) written without the tangent, finite at grazing.
    const double denom = c2 * (a2 - 1) + 1;
    return a2 / (kPi * denom * denom);
  }
  const double tan2 = (1 - c2) / c2;
  return std::exp(-tan2 / a2) / (kPi * a2 * c2 * c2);
}

double MicrofacetDistribution::lambda(const Vec3& w) const {
  if (w.z <= 0) return std::numeric_limits<double>::infinity();
  const double sin2 = std::max(0.0, 1 - w.z * w.z);
  if (sin2 == 0) return 0;
  const double tan2 = sin2 / (w.z * w.z);
  if (model == MicrofacetModel::kGgx) return 0.5 * (std::sqrt(1 + alpha * alpha * tan2) - 1);
  // Beckmann (Walter et al. 2007, eq. 25 before its rational approximation), exact form with
  // erfc to avoid the cancellation in erf(a) - 1.
  const double a = 1 / (alpha * std::sqrt(tan2));
  return 0.5 * (std::exp(-a * a) / (a * std::sqrt(kPi)) - std::erfc(a));
}

Vec3 MicrofacetDistribution::sample_normal(const Vec3& wo, Vec2 u) const {
  if (model == MicrofacetModel::kBeckmann) {
    // tan^2 theta_h = -alpha^2 ln(1 - u1), phi uniform: density D(h) h.z.
    const double tan2 = -alpha * alpha * std::log1p(-u.x);
    const double cos_t = 1 / std::sqrt(1 + tan2);
    const double sin_t = safe_sqrt(1 - cos_t * cos_t);
    const double phi = 2 * kPi * u.y;
    return {sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t};
  }
  // GGX visible normals (Heitz 2018): stretch wo to the unit-roughness configuration, sample the
  // projected hemisphere there, and unstretch the normal.
  const Vec3 v = normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});
  const double len2 = v.x * v.x + v.y * v.y;
  const Vec3 t1 = len2 > 0 ? Vec3{-v.y, v.x, 0} / std::sqrt(len2) : Vec3{1, 0, 0};
  const Vec3 t2 = cross(v, t1);
  const double r = std::sqrt(u.x);
  const double phi = 2 * kPi * u.y;
  const double p1 = r * std::cos(phi);
  const double s = 0.5 * (1 + v.z);
  const double p2 = (1 - s) * safe_sqrt(1 - p1 * p1) + s * r * std::sin(phi);
  const Vec3 nh = p1 * t1 + p2 * t2 + safe_sqrt(1 - p1 * p1 - p2 * p2) * v;
  return normalize(Vec3{alpha * nh.x, alpha * nh.y, std::max(1e-12, nh.z)});
}

double MicrofacetDistribution::pdf_normal(const Vec3& wo, const Vec3& h) const {
  if (h.z <= 0) return 0;
  if (model == MicrofacetModel::kBeckmann) return d(h) * h.z;
  const double wo_h = dot(wo, h);
  if (wo_h <= 0 || wo.z <= 0) return 0;
  return g1(wo) * wo_h * d(h) / wo.z;
}

}  // namespace weft
