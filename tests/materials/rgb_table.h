#pragma once
// An RGB table made from a function, for the table tests.
#include <functional>
#include <span>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft::testing {

// The 3-channel table of 'resolution' whose cells average f(wo, wi) over 'spp' samples per
// cell side (TabulatedBsdfTable::from_function, seed 1).
inline TabulatedBsdfTable rgb_table(int resolution,
                                    const std::function<Rgb(const Vec3&, const Vec3&)>& f,
                                    int spp = 16) {
  return TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb c = f(wo, wi);
        v[0] = c.r, v[1] = c.g, v[2] = c.b;
      },
      spp, 1);
}

}  // namespace weft::testing
