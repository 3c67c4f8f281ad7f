#pragma once
// Cook-Torrance microfacet reflection from a dielectric surface (Cook and Torrance, ACM TOG 1(1)
// 1982), with the modern normalization of Walter et al. 2007:
//   f(wo, wi) = tint * F(wo.h) D(h) G2(wo, wi) / (4 |cos theta_o| |cos theta_i|),  h = (wo+wi)/|.|
// F is the unpolarized dielectric Fresnel reflectance at index 'ior' (outside index 1), D is
// Beckmann or GGX, G2 is the height-correlated Smith term (reciprocal, see microfacet.h).
// Reflection only, on either side: for wo.z < 0 both directions are mirrored through the surface
// plane, so the back side is the same interface seen from below.
#include <optional>
#include <vector>

#include "weft/materials/bsdf.h"
#include "weft/materials/microfacet.h"

namespace weft {

inline constexpr double kCottonIor = 1.557;  // mean refractive index of cotton (paper, sec. 3.1)

struct CookTorranceBsdf {
  MicrofacetDistribution distribution;
  double ior = kCottonIor;
  Rgb tint{1.0};

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;

  // The untinted f for wo.z > 0, wi.z > 0 (0 otherwise); what eval and classic_fiber build on.
  double eval_upper(const Vec3& wo, const Vec3& wi) const;
  // The density of sample for wo.z > 0, wi.z > 0 (0 otherwise).
  double pdf_upper(const Vec3& wo, const Vec3& wi) const;
};

// Directional albedo of a Cook-Torrance lobe (a fiber's surface, surface_lobe.h) at cos theta,
// tabulated at nodes uniform in sqrt(cos theta) (dense at grazing angles) and interpolated
// linearly; computed by a deterministic stratified quadrature of the sample weights.
class SurfaceAlbedoTable {
 public:
  SurfaceAlbedoTable(MicrofacetModel model, double alpha, double ior, int nodes = 129,
                     int samples_per_side = 64);
  double operator()(double cos_theta) const;

 private:
  std::vector<double> albedo_;
};

}  // namespace weft
