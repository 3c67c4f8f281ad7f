#pragma once
// A rough dielectric interface as a random walk on its microsurface: the boundary of the fiber
// when its spec says "boundary": "rough-dielectric" (docs/fiber-bsdf.md).
//
// The microsurface is a Smith microsurface (Beckmann or GGX normals of roughness alpha,
// uncorrelated heights) between index n_outside (above, the side the normal points to) and n_inside
// (below). A photon meeting it walks on it until it leaves (Heitz, Hanika, d'Eon, Dachsbacher,
// "Multiple-scattering microfacet BSDFs with the Smith model", ACM TOG 35(4) 2016, sec. 3-5, their
// dielectric): at each step the next height follows from the Smith masking (the photon leaves with
// probability G1(w, h)), the microfacet normal from the distribution of visible normals (Heitz
// 2018 for GGX; Heitz and d'Eon 2014 for Beckmann), and Fresnel on that microfacet decides between
// reflection and refraction (Walter, Marschner, Li, Torrance 2007). Its first step alone is the
// single-scattering microfacet BSDF of Walter et al. with height-correlated masking-shadowing; the
// further steps are the light that model loses. The walk is exact for the Smith model, reciprocal
// and conserves energy: every photon leaves, above or below.
#include <cstdint>

#include "weft/core/rng.h"
#include "weft/core/vec.h"
#include "weft/materials/microfacet.h"

namespace weft {

struct RoughDielectricScatter {
  Vec3 direction;        // travelling direction after the interface, local frame (unit)
  bool outside = false;  // left above (direction.z > 0) or below (direction.z < 0)
  bool lost = false;     // the walk hit kMaxOrder steps (booked as lost; never seen in practice)
  int order = 0;         // microsurface interactions (1: single scattering)
};

// Reflectance and transmittance of one interface for light from a direction above it.
struct RoughDielectricAlbedo {
  double reflected = 0, transmitted = 0;
};

class RoughDielectricInterface {
 public:
  static constexpr int kMaxOrder = 100000;

  // alpha in (0, 1], indices finite and >= 1e-6; throws weft::Error naming the field.
  RoughDielectricInterface(MicrofacetModel model, double alpha, double n_outside, double n_inside);

  // A photon travelling along unit 'd' (local frame, z = the normal pointing outside) meets the
  // interface: from outside when d.z < 0, from inside when d.z > 0 (d.z = 0: from outside).
  // Deterministic given rng; index-matched interfaces pass the photon straight, drawing nothing.
  RoughDielectricScatter scatter(const Vec3& d, Rng& rng) const;

  // Single scattering only (the walk's first step), for light from unit 'w' (w.z > 0: the
  // direction towards the light, above the interface): the reflected and transmitted fractions,
  // by quadrature over the microfacet normals (D and Lambda, not the walk's sampling). One minus
  // their sum is what a single-scattering model loses. 'from_inside' puts the light below
  // (mirrored: w.z > 0 still).
  RoughDielectricAlbedo single_scatter_albedo(const Vec3& w, bool from_inside = false,
                                              int theta_nodes = 1024, int phi_nodes = 256) const;

  const MicrofacetDistribution& distribution() const { return dist_; }
  double n_outside() const { return n_outside_; }
  double n_inside() const { return n_inside_; }

  // A visible normal for w (w.z > 0) of the distribution (Heitz 2018 for GGX, Heitz and d'Eon
  // 2014 for Beckmann): density G1(w) max(0, w.h) D(h) / w.z.
  Vec3 sample_visible_normal(const Vec3& w, Vec2 u) const;
  // Smith's Lambda on both sides: Lambda(w) for w.z > 0, -1 - Lambda(-w) for w.z < 0 (Heitz et
  // al. 2016, eq. 6 and sec. 3.2).
  double lambda(const Vec3& w) const;

 private:
  MicrofacetDistribution dist_;
  double n_outside_, n_inside_;
};

}  // namespace weft
