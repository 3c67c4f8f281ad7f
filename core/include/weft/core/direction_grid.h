#pragma once
// The one mapping between directions and table bins (fiber and fabric BSDF tables, the bakers'
// tallies, the BSSRDF's exit directions). Each hemisphere of the local frame (z >= 0 upper, z < 0
// lower) has its own equal-area square: the octahedral map's upper diamond (sphere_mapping.h)
// turned by 45 degrees, with the horizon on the square's edges. R x R bins per hemisphere, 2 R^2
// in all, each of solid angle 2 pi / R^2; no bin straddles the horizon, so reflection and
// transmission never share a bin and interpolation never blends across the horizon.
//
// The chart stacks the two squares in [0,1] x [0,1]: x across, y < 1/2 the upper hemisphere and
// y >= 1/2 the lower one (both squares in the same orientation, the lower one mirrored through
// z = 0). Bin index = row * R + column with row = floor(2 R y), i.e. hemisphere * R^2 + y_h * R + x
// for the cell (x, y_h) of its square; an area A of the chart covers the solid angle 4 pi A.
#include <vector>

#include "weft/core/vec.h"

namespace weft {

struct DirectionGrid {
  int resolution = 0;  // R: bins per side of each hemisphere's square

  int bins() const { return 2 * resolution * resolution; }
  double bin_solid_angle() const;  // 2 pi / R^2
  static Vec2 to_chart(const Vec3& d);
  static Vec3 to_direction(Vec2 chart);
  int bin_of_chart(Vec2 chart) const;
  int bin_of(const Vec3& d) const { return bin_of_chart(to_chart(d)); }
  Vec3 bin_center(int bin) const;
  bool upper(int bin) const { return bin < resolution * resolution; }
  // The chart point of bin 'bin' at offsets (fx, fy) in [0, 1] across the bin.
  Vec2 chart_point(int bin, double fx, double fy) const;
  // The bin of the mirror images of bin's directions through the plane x = 0 (axis 0), y = 0
  // (axis 1) or z = 0 (axis 2): the grid is symmetric under all three.
  int mirrored_bin(int bin, int axis) const;

  // Bilinear interpolation footprint of chart point p over the 4 nearest bin centres of its own
  // hemisphere, clamped at the square's edges (the horizon): never across the horizon.
  struct Footprint {
    int bin[4];
    double weight[4];
  };
  Footprint bilinear(Vec2 chart) const;

  // D_k = integral over bin k of |cos theta| d omega (exact, to rounding): the weight of a
  // cosine-weighted cell average; sum_k D_k = 2 pi.
  std::vector<double> cosine_weighted_areas() const;
};

}  // namespace weft
