#pragma once
// A synthetic sharp sheen for the tests of tables that hold one (half_vector_lobe.h): Q (the lobe's
// F D G, f = Q / (4 |cos_i| |cos_o|)) a Gaussian of the half vector's angle from the normal,
// 'peak' at the pole and 'sigma_deg' wide, the same for every light bin and channel. At the
// default grid (R_h 64, window 16: bins 2.2 degrees across, the fabric ray trace's defaults,
// docs/fabric-bsdf.md) a sigma of 3 degrees is a satin-like peak a few bins wide, which the cells
// of an R 8 table (bins about 18 degrees across) blur away.
#include <algorithm>
#include <cmath>

#include "weft/core/math.h"
#include "weft/materials/half_vector_lobe.h"

namespace weft::testing {

inline HalfVectorLobe gaussian_sheen(int resolution, int channels, double peak, double sigma_deg,
                                     int h_resolution = 64, int window = 16) {
  HalfVectorLobe l = HalfVectorLobe::zeros(resolution, h_resolution, window, channels);
  const double sigma = deg_to_rad(sigma_deg);
  for (int k = 0; k < l.window_bins(); ++k) {
    const double theta_h = std::acos(std::min(1.0, l.window_point(k, 0.5, 0.5).z));
    const auto q = static_cast<float>(peak * std::exp(-theta_h * theta_h / (2 * sigma * sigma)));
    for (int a = 0; a < 2 * resolution * resolution; ++a)
      for (int c = 0; c < channels; ++c) l.values[l.index(a, k, c)] = q;
  }
  return l;
}

}  // namespace weft::testing
