#pragma once
// What every material's sample() returns, and the cosine-hemisphere warp several of them share.
// The conventions these obey are stated once, in bsdf.h.
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft {

struct BsdfSample {
  Vec3 wi;
  Rgb weight;      // f * |cos theta_i| / pdf
  double pdf = 0;  // solid-angle density of wi
  bool is_delta = false;
};

// Cosine-weighted direction on the upper (z > 0) hemisphere (Malley's method).
Vec3 sample_cosine_hemisphere(Vec2 u);

}  // namespace weft
