#pragma once
// The fiber table as the fiber-level ray trace (fabric_raytrace.h) draws from it: per light bin i
// and sampling strategy s the albedo A_s[i] = sum_o g_s[i][o] D_o and a distribution over exit
// cells o with weights g_s[i][o] D_o, where g_s is the mean of f over the channels of group s, and
// the same for all channels' mean (strategy index 'groups': the estimator before spectral MIS);
// within a cell, directions are drawn in proportion to |cos theta|.
//
// With the table's surface lobe kept exact (materials/surface_lobe.h; 'table' then holds the rest
// of f, TabulatedBsdfTable::without_surface_lobe), a scattering may draw its exit from the lobe
// itself: a filament's first-surface reflection, narrower than the bins, is then never averaged
// over a cell. The fiber read this way is, for light from wi in bin i and channel c,
//   f_c(wi, wo) = rest_c[i][o] k_c(wi) + lobe_c(wi, wo),
//   k_c(wi) = max(0, A_c[i] + L_c[i] - rho_c(wi)) / A_c[i],
// A_c and L_c the rest's and the lobe's albedos over bin i (their cells'), rho_c(wi) the lobe's
// own albedo at wi: the light the lobe reflects at wi is what does not enter (the paper's 1 - rho
// at the entry), so the total albedo at every wi is the table's over its bin, as a reader of the
// cells alone has it, and the cell averages of f are the table's cells. Without k the exact lobe
// beside the bin-averaged rest gave a lossless filament satin 2 % more light than it received.
//
// There are kChannelGroups groups: an RGB table's three channels, a spectral table's thirds of
// adjacent bands (at most kChannelGroups channels: one each). One strategy per band drew the same
// paths as its neighbours (a dye's spectrum changes little over a few 10 nm bands) for 1.1x the
// CPU: each strategy's rows are what a scattering reads from memory, 9 MB for 33 bands at R = 8,
// several times the cache (docs/PERFORMANCE.md). Every channel keeps a strategy that draws
// wherever its f is non-zero (a group's mean is at least f_c over the group's size), so MIS over
// the groups stays unbiased.
#include <span>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/distribution.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/cook_torrance.h"

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

  // The exact lobe beside 'table' (null: none); per light bin and strategy its cells' albedo, the
  // strategy's channels' mean of sum_o lobe cell [i][o] D_o; per bin and channel A_c and L_c; the
  // lobe's directional albedo per distinct index, and which of them each channel has.
  const SurfaceLobe* lobe = nullptr;
  std::vector<double> lobe_albedo;                   // [i * strategies + s]; empty without a lobe
  std::vector<double> rest_albedo_c, lobe_albedo_c;  // [i * channels + c]
  std::vector<SurfaceAlbedoTable> lobe_albedo_tables;
  std::vector<int> albedo_table_of_channel;

  explicit FiberSampler(const TabulatedBsdfTable& t);
  // 'rest' the table without its lobe, 'lobe_cells' the lobe's cell averages on its grid
  // (SurfaceLobe::cell_averages); both held by the caller for the sampler's life.
  FiberSampler(const TabulatedBsdfTable& rest, const SurfaceLobe& lobe,
               const std::vector<double>& lobe_cells);

  double lobe_albedo_of(int bin, int s) const {
    return lobe ? lobe_albedo[static_cast<size_t>(bin) * strategies + s] : 0.0;
  }
  // For light from wi (local frame) in bin i: the lobe's own albedo rho_c(wi) and the rest's
  // scale k_c(wi) per channel (see above), each 'channels' values.
  void exact_lobe_split(int bin, const Vec3& wi, std::span<double> rho, std::span<double> k) const;
  // The channels' mean of x over strategy s's channels.
  double group_mean(std::span<const double> x, int s) const;

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
