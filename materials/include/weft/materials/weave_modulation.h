#pragma once
// A weave table (weave_table.h) prepared for shading, and what a fabric_table material that names
// one carries (TableWeave). The table level of such a material is its TabulatedBsdf alone; the
// weave level multiplies it by the modulation at the hit's place in the repeat (bound_bsdf.h):
//   f(x, wo, wi) = f_table(wo, wi) * m(x, wo, wi).
// Lookup: the modulation is read between cells as the table is, bilinearly: over the positions,
// between the 4 cells whose centres surround x on the torus of the repeat (no blocky cells, and
// the mean over the repeat of the blend is the mean of the cells, 1), and over directions on the
// coarse DirectionGrid (for_each_interpolated_cell, bsdf_table.h).
// Channels: RGB as stored; a spectral weave per band for spectral renders, and for RGB renders
// reduced per channel c to the mean over the bands weighted by the positive part of each band's
// D65 sRGB weight for c (spectrum.h srgb_band_weights_d65): an average of band modulations, so
// non-negative and of mean 1 over the repeat, as the bands are. (The exact RGB of f_table * m
// would weight the bands by f_table too; across a channel's bands m varies little.)
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"
#include "weft/materials/weave_table.h"

namespace weft {

// Where a point lies in the repeat: the 4 position cells around it and their bilinear weights.
struct WeavePoint {
  std::array<uint32_t, 4> pos{};
  std::array<double, 4> weight{};
};

class WeaveModulation {
 public:
  // From a validated table.
  explicit WeaveModulation(WeaveTable table);

  // The point of texture coordinates uv (uv_metres metres per unit; u along the table's x).
  WeavePoint locate(Vec2 uv, double uv_metres) const;
  // m(x, wo, wi) per RGB channel (wo, wi in the table's frame).
  Rgb rgb(const WeavePoint& at, const Vec3& wo, const Vec3& wi) const;
  // m(x, wo, wi) per band into 'out'; for a spectral table only (has_bands).
  void bands(const WeavePoint& at, const Vec3& wo, const Vec3& wi, Spectrum& out) const;
  bool has_bands() const { return !bands_.empty(); }
  // The table's sizes and metadata; its values moved into the modulation (modulation is empty).
  const WeaveTable& table() const { return table_; }

 private:
  // Sums weight * m[pos][wi bin][wo bin][0 .. channels) over the interpolated cells into 'out'.
  template <class Out>
  void blend(const std::vector<float>& values, int channels, const WeavePoint& at, const Vec3& wo,
             const Vec3& wi, Out& out) const;

  WeaveTable table_;
  DirectionGrid grid_;
  std::vector<float> rgb_;    // [pos][wi_bin][wo_bin][3]: the table's, or its bands reduced
  std::vector<float> bands_;  // a spectral table's values as stored; else empty
};

// fabric_table's "level".
enum class WeaveLevel { automatic, weave, table };

// A fabric_table's weave (its params "weave", "level", "uv_metres", "weave_min_pixels").
struct TableWeave {
  std::shared_ptr<const WeaveModulation> modulation;
  WeaveLevel level = WeaveLevel::automatic;
  double uv_metres = 1;   // metres per UV unit
  double min_pixels = 4;  // auto: the weave level from this many pixels per repeat
  std::string file;       // the weave table's file, for reports
};

}  // namespace weft
