#include "weft/fabric/line_albedo.h"

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// Axial cosines tabulated (midpoints of equal steps over [-1, 1]: a line along the axis meets the
// fiber's surface nowhere, and its light would fall on the horizon of both points), and impact
// parameters per line (the midpoint rule over a function that is constant within the table's bins:
// its error is about the bins' jumps over kImpactSteps).
constexpr int kAxialSteps = 256, kImpactSteps = 1024;

}  // namespace

LineAlbedo::LineAlbedo(const TabulatedBsdfTable& fiber) : channels_(fiber.channels) {
  const DirectionGrid grid = fiber.grid();
  const int bins = grid.bins(), nc = channels_;
  point_.resize(static_cast<size_t>(bins) * nc);
  for (int b = 0; b < bins; ++b) {
    const TabulatedBsdfTable::DirectionalAlbedo a = fiber.directional_albedo(b);
    for (int c = 0; c < nc; ++c) point_[static_cast<size_t>(b) * nc + c] = a.total(c);
  }
  // The line along d = s axis + p across (p = sqrt(1 - s^2)) at impact u enters the fiber where
  // the outward normal is n' = u side - c across and leaves where it is n'' = u side + c across
  // (c = sqrt(1 - u^2), side = axis x across). In a point's fiber frame (x = axis, y = n x axis,
  // z = n) the light comes from -d = (-s, -p u, p c) at B' and (-s, -p u, -p c) at B''.
  line_.assign(static_cast<size_t>(kAxialSteps) * nc, 0.0);
  for (int k = 0; k < kAxialSteps; ++k) {
    const double s = -1 + (k + 0.5) * 2.0 / kAxialSteps, p = std::sqrt(1 - s * s);
    double* sum = &line_[static_cast<size_t>(k) * nc];
    for (int i = 0; i < kImpactSteps; ++i) {
      const double u = -1 + (i + 0.5) * 2.0 / kImpactSteps, c = std::sqrt(1 - u * u);
      const int entry = grid.bin_of({-s, -p * u, p * c}), exit = grid.bin_of({-s, -p * u, -p * c});
      for (int ch = 0; ch < nc; ++ch) sum[ch] += point(entry, ch) + point(exit, ch);
    }
    for (int ch = 0; ch < nc; ++ch) sum[ch] /= kImpactSteps;
  }
}

double LineAlbedo::line(double axial, int c) const {
  const double x = std::clamp((axial + 1) * 0.5 * kAxialSteps - 0.5, 0.0, kAxialSteps - 1.0);
  const int k = std::min(kAxialSteps - 2, static_cast<int>(x));
  const double t = x - k;
  return (1 - t) * line_[static_cast<size_t>(k) * channels_ + c] +
         t * line_[static_cast<size_t>(k + 1) * channels_ + c];
}

}  // namespace weft
