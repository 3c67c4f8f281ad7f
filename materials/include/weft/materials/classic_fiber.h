#pragma once
// The paper's baseline fiber ("classic way", Voloboy et al. 2010, sec. 4.1): a Cook-Torrance
// surface reflection plus a Lambert volume part.
//
// Coupling (our choice, stated because the paper does not give one): the volume part receives the
// energy the specular part leaves, in a reciprocal form (Kelemen and Szirmay-Kalos, "A microfacet
// based coupled specular-matte BRDF model with importance sampling", Eurographics 2001):
//   f = f_ct(wo, wi) + reflectance / pi * (1 - E(mu_o)) (1 - E(mu_i)) / (1 - E_avg)
// where E(mu) is the directional albedo of the untinted Cook-Torrance part and
// E_avg = 2 int_0^1 E(mu) mu dmu. Its directional albedo is then exactly
//   E(mu_o) + reflectance (1 - E(mu_o)),
// so 'reflectance' is the albedo of the light that enters the fiber, and reflectance = 1 is
// lossless. E is tabulated once per material at 33 values of mu (deterministic quadrature) and
// interpolated linearly; E_avg is the exact integral of that interpolant, so the identity above
// holds up to the tabulation error of E.
//
// Sampling: a lobe is chosen with probability proportional to its albedo at wo (E for the
// surface, mean(reflectance)(1 - E) for the volume); the volume lobe is cosine-sampled; pdf is the
// mixture. Reflection only, on either side (wo.z < 0 is mirrored).
#include <array>
#include <memory>
#include <optional>

#include "weft/core/progress.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/cook_torrance.h"

namespace weft {

// Directional albedo E(mu) of an untinted Cook-Torrance surface, tabulated in mu = |cos theta|.
struct SpecularAlbedoTable {
  static constexpr int kNodes = 33;
  std::array<double, kNodes> albedo{};  // E at mu_k = k / (kNodes - 1)
  double average = 0;                   // 2 int_0^1 E(mu) mu dmu of the interpolant

  static SpecularAlbedoTable compute(const CookTorranceBsdf& surface);
  double operator()(double mu) const;
};

struct ClassicFiberBsdf {
  Rgb reflectance{0.5};  // albedo of the volume (Lambert) part, each in [0, 1]
  CookTorranceBsdf surface;
  std::shared_ptr<const SpecularAlbedoTable> surface_albedo;  // of 'surface', untinted

  // Builds the material and its albedo table (about a few ms). surface.tint must be 1.
  static ClassicFiberBsdf create(Rgb reflectance, MicrofacetDistribution distribution,
                                 double ior = kCottonIor);

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;

  // Probability of choosing the surface lobe at wo (mirrored to the upper side).
  double surface_lobe_probability(const Vec3& wo_upper) const;
};

// The classic fiber (outer hemisphere only: opaque) as a fiber table of R = 'resolution', 3
// channels, 'samples' direction pairs per cell pair (TabulatedBsdfTable::from_function): what the
// fabric ray trace and the summations read in place of a baked fiber table.
TabulatedBsdfTable classic_fiber_table(const Rgb& diffuse, const MicrofacetDistribution& d,
                                       double ior, int resolution, int samples, uint64_t seed,
                                       int threads,
                                       const ProgressCallback& progress = no_progress());

}  // namespace weft
