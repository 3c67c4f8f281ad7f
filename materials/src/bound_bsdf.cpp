#include "weft/materials/bound_bsdf.h"

namespace weft {

void eval_bands(const BoundBsdf& b, const Vec3& wo, const Vec3& wi, Spectrum& out) {
  eval_bands(*b.bsdf, wo, wi, out);
  if (!b.weave) return;
  Spectrum m;
  b.weave->bands(b.at, wo, wi, m);
  for (int k = 0; k < kNumBands; ++k) out[k] *= m[k];
}

void sample_weight_bands(const BoundBsdf& b, const Vec3& wo, const BsdfSample& s, Spectrum& out) {
  sample_weight_bands(*b.bsdf, wo, s, out);
  if (!b.weave) return;
  Spectrum m;
  b.weave->bands(b.at, wo, s.wi, m);
  for (int k = 0; k < kNumBands; ++k) out[k] *= m[k];
}

}  // namespace weft
