#pragma once
// The fiber table as the fiber-level ray trace (fabric_raytrace.h) draws from it: per light bin i
// and sampling strategy s the albedo A_s[i] = sum_o g_s[i][o] D_o and a distribution over exit
// cells o with weights g_s[i][o] D_o, where g_s is the mean of f over the channels of group s, and
// the same for all channels' mean (strategy index 'groups': the estimator before spectral MIS);
// within a cell, directions are drawn in proportion to |cos theta|.
//
// There are kChannelGroups groups: an RGB table's three channels, a spectral table's thirds of
// adjacent bands (at most kChannelGroups channels: one each). One strategy per band drew the same
// paths as its neighbours (a dye's spectrum changes little over a few 10 nm bands) for 1.1x the
// CPU: each strategy's rows are what a scattering reads from memory, 9 MB for 33 bands at R = 8,
// several times the cache (docs/PERFORMANCE.md). Every channel keeps a strategy that draws
// wherever its f is non-zero (a group's mean is at least f_c over the group's size), so MIS over
// the groups stays unbiased.
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/distribution.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

inline constexpr int kChannelGroups = 3;

struct FiberSampler {
  const TabulatedBsdfTable* table = nullptr;
  DirectionGrid grid;
  int groups = 0;      // channel groups, one strategy each (the MIS strategies)
  int strategies = 0;  // groups + 1 (all channels' mean)
  int group_size = 1;  // channels per group (the last may have fewer)
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
  // The table value that strategy s samples in proportion to: its channels' mean.
  double value(int i, int o, int s) const;
  // The channels [first, last) of strategy s.
  int first_channel(int s) const { return s < groups ? s * group_size : 0; }
  int last_channel(int s) const;
  // A direction in cell b with density proportional to |cos theta| (rejection against the bound).
  Vec3 cosine_direction_in(int b, Rng& rng) const;
};

}  // namespace weft
