#pragma once
// Isotropic microfacet normal distributions with Smith masking-shadowing, in the local frame of
// the macro-surface (z up). Only the upper hemisphere is handled here; materials mirror the back
// side onto it.
//
// References: Walter, Marschner, Li, Torrance, "Microfacet models for refraction through rough
// surfaces", EGSR 2007 (D and Lambda of Beckmann and GGX); Heitz, "Understanding the
// masking-shadowing function in microfacet-based BRDFs", JCGT 3(2) 2014 (height-correlated
// Smith G2 = 1 / (1 + Lambda(wo) + Lambda(wi)), visible-normal density); Heitz, "Sampling the GGX
// distribution of visible normals", JCGT 7(4) 2018.
#include <string>

#include "weft/core/vec.h"

namespace weft {

enum class MicrofacetModel { kBeckmann, kGgx };

// "beckmann" / "ggx".
const char* microfacet_model_name(MicrofacetModel model);

struct MicrofacetDistribution {
  MicrofacetModel model = MicrofacetModel::kGgx;
  double alpha = 0.3;  // roughness: RMS slope (Beckmann), width (GGX)

  // Density of microfacet normals h (h.z > 0, else 0), normalized so that the projected area
  // integral over the hemisphere is 1: integral D(h) h.z dw_h = 1.
  double d(const Vec3& h) const;
  // Smith's Lambda for a direction w with w.z > 0 (0 at the pole, +inf at the horizon).
  double lambda(const Vec3& w) const;
  // Smith masking of one direction, and the height-correlated masking-shadowing of a pair.
  double g1(const Vec3& w) const { return 1.0 / (1.0 + lambda(w)); }
  double g2(const Vec3& wo, const Vec3& wi) const { return 1.0 / (1.0 + lambda(wo) + lambda(wi)); }

  // Draws a microfacet normal for the given wo (wo.z > 0). GGX: the distribution of visible
  // normals D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Heitz 2018). Beckmann: the classic
  // D(h) h.z sampling (Walter et al. 2007, eq. 28), which ignores wo.
  Vec3 sample_normal(const Vec3& wo, Vec2 u) const;
  // Solid-angle density of sample_normal's h.
  double pdf_normal(const Vec3& wo, const Vec3& h) const;
};

}  // namespace weft
