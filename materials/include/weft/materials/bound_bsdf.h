#pragma once
// A material as a renderer shades it at one hit: the scene's Bsdf, and for a fabric_table at its
// weave level (weave_modulation.h) the weave's modulation at the hit's place in the repeat.
// Every other material is its Bsdf alone (weave null): one test of a pointer more per call.
//   eval:   f_table(wo, wi) * m(x, wo, wi)
//   sample: the table's sample, its weight times m (the density is the table's: it is > 0
//           wherever f_table > 0, so the estimate stays unbiased)
//   pdf:    the table's
// The same in bands for spectral renders (a spectral weave's bands; bsdfs.h eval_bands).
#include <optional>

#include "weft/materials/bsdfs.h"
#include "weft/materials/weave_modulation.h"

namespace weft {

struct BoundBsdf {
  const Bsdf* bsdf = nullptr;
  const WeaveModulation* weave = nullptr;  // null: no weave level here
  WeavePoint at;                           // the hit's place in the repeat (with 'weave')

  Rgb eval(const Vec3& wo, const Vec3& wi) const {
    const Rgb f = bsdf->eval(wo, wi);
    return weave && !f.is_black() ? f * weave->rgb(at, wo, wi) : f;
  }
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const {
    auto s = bsdf->sample(wo, u, u_lobe);
    if (s && weave) s->weight *= weave->rgb(at, wo, s->wi);
    return s;
  }
  double pdf(const Vec3& wo, const Vec3& wi) const { return bsdf->pdf(wo, wi); }
};

// bsdfs.h eval_bands and sample_weight_bands of the bound material, modulated per band.
void eval_bands(const BoundBsdf& b, const Vec3& wo, const Vec3& wi, Spectrum& out);
void sample_weight_bands(const BoundBsdf& b, const Vec3& wo, const BsdfSample& s, Spectrum& out);

}  // namespace weft
