#pragma once
// The fiber table as the fiber-level ray trace (fabric_raytrace.h) draws from it: per light bin i
// and channel c the albedo A_c[i] = sum_o f_c[i][o] D_o and a distribution over exit cells o with
// weights f_c[i][o] D_o, and the same for the channels' mean (strategy index channels: the
// estimator before spectral MIS); within a cell, directions are drawn in proportion to
// |cos theta|.
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/distribution.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct FiberSampler {
  const TabulatedBsdfTable* table = nullptr;
  DirectionGrid grid;
  int strategies = 0;  // channels + 1 (their mean)
  std::vector<double> areas, max_cos;
  std::vector<double> albedo;        // [i * strategies + s]
  std::vector<Distribution1D> rows;  // [i * strategies + s]

  explicit FiberSampler(const TabulatedBsdfTable& t);

  double albedo_of(int bin, int s) const {
    return albedo[static_cast<size_t>(bin) * strategies + s];
  }
  const Distribution1D& row(int bin, int s) const {
    return rows[static_cast<size_t>(bin) * strategies + s];
  }
  // The table value that strategy s samples in proportion to.
  double value(int i, int o, int s) const;
  // A direction in cell b with density proportional to |cos theta| (rejection against the bound).
  Vec3 cosine_direction_in(int b, Rng& rng) const;
};

}  // namespace weft
