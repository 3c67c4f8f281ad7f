#pragma once
// A table every verify test can predict: f constant.
#include <numbers>
#include <span>

#include "weft/materials/bsdf_table.h"

namespace weft::testing {

// A table of f = c / pi: beta = pi f = c at every incidence and view (the cell average of a
// constant is exact, bsdf_table.h).
inline TabulatedBsdfTable constant_table(int resolution, int channels, double beta) {
  return TabulatedBsdfTable::from_function(
      resolution, channels,
      [beta](const Vec3&, const Vec3&, std::span<double> v) {
        for (double& x : v) x = beta / std::numbers::pi;
      },
      2, 1, 1);
}

}  // namespace weft::testing
