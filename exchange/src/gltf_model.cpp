#include <algorithm>
#include <cmath>

#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/exchange/gltf_material.h"

namespace weft {
namespace {

// KHR_materials_sheen's fit of the Charlie lambda (its "Sheen visibility").
double sheen_l(double x, double alpha) {
  const double t = sqr(1 - alpha);
  const auto mix = [t](double a, double b) { return a + (b - a) * t; };
  return mix(21.5473, 25.3245) / (1 + mix(3.82987, 3.32435) * std::pow(x, mix(0.19823, 0.16801))) +
         mix(-1.97760, -1.27393) * x + mix(-4.32054, -4.85967);
}
double sheen_lambda(double cos_theta, double alpha) {
  return std::abs(cos_theta) < 0.5
             ? std::exp(sheen_l(cos_theta, alpha))
             : std::exp(2 * sheen_l(0.5, alpha) - sheen_l(1 - cos_theta, alpha));
}

constexpr int kAlbedoNodes = 32;

}  // namespace

double charlie_sheen(double sheen_roughness, const Vec3& wo, const Vec3& wi) {
  const double nv = wo.z, nl = wi.z;
  if (nv <= 0 || nl <= 0) return 0;
  const double alpha = std::max(sheen_roughness, 1e-3);
  const Vec3 h = normalize(wo + wi);
  const double sin2h = std::max(0.0, 1 - h.z * h.z);
  const double d = (2 + 1 / alpha) * std::pow(sin2h, 0.5 / alpha) / (2 * kPi);
  const double v = 1 / ((1 + sheen_lambda(nv, alpha) + sheen_lambda(nl, alpha)) * (4 * nv * nl));
  return d * v;
}

SheenAlbedo::SheenAlbedo(double sheen_roughness) {
  // E(mu) = int charlie cos theta_l d omega_l, midpoint rule in (cos theta_l, phi_l).
  constexpr int kCos = 48, kPhi = 48;
  for (int k = 0; k < kAlbedoNodes; ++k) {
    const double mu = std::max(1e-3, static_cast<double>(k) / (kAlbedoNodes - 1));
    const Vec3 wo{std::sqrt(1 - mu * mu), 0, mu};
    double sum = 0;
    for (int a = 0; a < kCos; ++a) {
      const double cl = (a + 0.5) / kCos;
      for (int b = 0; b < kPhi; ++b) {
        const double phi = kPi * (b + 0.5) / kPhi;  // symmetric in phi: half the circle, twice
        sum += charlie_sheen(sheen_roughness, wo, spherical_direction(std::acos(cl), phi)) * cl;
      }
    }
    e_.push_back(sum * (1.0 / kCos) * (2 * kPi / kPhi));
  }
}

double SheenAlbedo::operator()(double cos_theta) const {
  const double x = std::clamp(cos_theta, 0.0, 1.0) * (kAlbedoNodes - 1);
  const int j = std::min(static_cast<int>(x), kAlbedoNodes - 2);
  return e_[static_cast<size_t>(j)] +
         (e_[static_cast<size_t>(j + 1)] - e_[static_cast<size_t>(j)]) * (x - j);
}

Rgb gltf_brdf(const GltfMaterial& m, const SheenAlbedo& e, const Vec3& wo, const Vec3& wi) {
  const double nv = wo.z, nl = wi.z;
  if (nv <= 0 || nl <= 0) return {};
  const Vec3 h = normalize(wo + wi);
  const double nh = h.z, vh = std::abs(dot(wo, h));
  const double a2 = sqr(sqr(m.roughness));
  const double d = nh > 0 ? a2 / (kPi * sqr(nh * nh * (a2 - 1) + 1)) : 0;
  const double vis =
      1 / ((nl + std::sqrt(a2 + (1 - a2) * nl * nl)) * (nv + std::sqrt(a2 + (1 - a2) * nv * nv)));
  const double fresnel = 0.04 + 0.96 * std::pow(1 - vh, 5);
  const double spec = fresnel * vis * d;
  const double diffuse = (1 - fresnel) * (1 - m.transmission) * (1 - m.diffuse_transmission) / kPi;
  const double sheen = charlie_sheen(m.sheen_roughness, wo, wi);
  const double smax = m.sheen_color.max_component();
  const double scaling = std::min(1 - smax * e(nv), 1 - smax * e(nl));
  Rgb f;
  for (int c = 0; c < 3; ++c)
    f[c] = m.sheen_color[c] * sheen + (m.base_color[c] * diffuse + spec) * scaling;
  return f;
}

Rgb gltf_btdf(const GltfMaterial& m, const SheenAlbedo& e, const Vec3& wo, const Vec3& wi) {
  if (wo.z <= 0 || wi.z >= 0 || m.diffuse_transmission <= 0) return {};
  const Vec3 mirrored{wi.x, wi.y, -wi.z};
  const double vh = std::abs(dot(wo, normalize(wo + mirrored)));
  const double fresnel = 0.04 + 0.96 * std::pow(1 - vh, 5);
  const double smax = m.sheen_color.max_component();
  const double scaling = std::min(1 - smax * e(wo.z), 1 - smax * e(-wi.z));
  return m.diffuse_transmission_color *
         ((1 - fresnel) * (1 - m.transmission) * m.diffuse_transmission / kPi * scaling);
}

}  // namespace weft
