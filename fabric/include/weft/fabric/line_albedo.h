#pragma once
// A round fiber's albedo for light along one line direction, from its whole-fiber table
// (docs/fiber-bsdf.md): the light the fiber sends out, as a fraction of the light its lines bring,
// averaged over where the lines cross it (the impact parameter, uniform over the fiber's width).
// A line at impact u (in radii) lights B' and B'' (fabric_raytrace.h), and the table returns
// A(B') + A(B'') of it, A the table's directional albedo at each point for the light's bin there;
// the table conserves energy only averaged over u, where a clear fiber's A' + A'' runs from about
// 0.5 near its edges to 2-3 through its axis. The average depends only on the line's axial cosine
// s = d . axis (the fiber is round). Averaged over isotropic light (weighted by the fiber's
// projected width, sqrt(1 - s^2)), it is the table's total albedo.
//
// The yarn tubes of the fiber-level ray trace stand for such a fiber: a tube crossing returns
// line(s) of its light (raytrace_steps.h, weigh_as_round_fiber).
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

class LineAlbedo {
 public:
  explicit LineAlbedo(const TabulatedBsdfTable& fiber);

  // The table's directional albedo (reflected + transmitted) for light from bin 'bin' of the
  // fiber's frame, in channel c.
  double point(int bin, int c) const { return point_[static_cast<size_t>(bin) * channels_ + c]; }
  // The line albedo in channel c for light along a direction whose cosine with the fiber's axis is
  // 'axial', interpolated between tabulated axial cosines (held beyond the outermost).
  double line(double axial, int c) const;

 private:
  int channels_ = 0;
  std::vector<double> point_;  // [bin * channels + c]
  std::vector<double> line_;   // [k * channels + c] at axial cosines -1 + (2 k + 1) / kAxialSteps
};

}  // namespace weft
