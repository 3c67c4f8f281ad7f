#include "marginal_warp.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"

namespace weft::rgl {

double invert_linear_segment(double target, double width, double a, double b) {
  // width (a s + (b - a) s^2 / 2) = target, solved in the form that stays exact as b -> a.
  const double c = target / width;
  const double q = a * a + 2 * (b - a) * c;
  const double den = a + std::sqrt(std::max(0.0, q));
  if (den <= 0) return 0;
  return std::clamp(2 * c / den, 0.0, 1.0);
}

MarginalWarp::MarginalWarp(std::vector<double> density, int width, int height)
    : v_(std::move(density)), w_(width), h_(height) {
  if (w_ < 2 || h_ < 2 || v_.size() != static_cast<size_t>(w_ * h_))
    throw Error("", "vndf", "the warp's grid needs at least 2 x 2 values");
  const double dx = 1.0 / (w_ - 1), dy = 1.0 / (h_ - 1);
  cond_.assign(v_.size(), 0);
  for (int y = 0; y < h_; ++y)
    for (int x = 1; x < w_; ++x)
      cond_[static_cast<size_t>(y * w_ + x)] = cond(x - 1, y) + dx * (at(x - 1, y) + at(x, y)) / 2;
  marginal_.assign(static_cast<size_t>(h_), 0);
  for (int y = 1; y < h_; ++y)
    marginal_[static_cast<size_t>(y)] =
        marginal_[static_cast<size_t>(y - 1)] + dy * (cond(w_ - 1, y - 1) + cond(w_ - 1, y)) / 2;
  if (!(marginal_.back() > 0)) throw Error("", "vndf", "the density is zero everywhere");
}

Vec2 MarginalWarp::sample(Vec2 u) const {
  const double dx = 1.0 / (w_ - 1), dy = 1.0 / (h_ - 1);
  // The row: the last vertex row whose marginal CDF is below the target.
  const double ty = std::clamp(u.y, 0.0, 1.0) * marginal_.back();
  int row = static_cast<int>(std::upper_bound(marginal_.begin(), marginal_.end(), ty) -
                             marginal_.begin()) -
            1;
  row = std::clamp(row, 0, h_ - 2);
  const double r0 = cond(w_ - 1, row), r1 = cond(w_ - 1, row + 1);
  const double sy = invert_linear_segment(ty - marginal_[static_cast<size_t>(row)], dy, r0, r1);
  // The column, in the conditional density at that y (the rows' CDFs blended alike).
  const double tx = std::clamp(u.x, 0.0, 1.0) * (r0 + (r1 - r0) * sy);
  auto cdf = [&](int x) { return cond(x, row) + (cond(x, row + 1) - cond(x, row)) * sy; };
  int col = 0;
  while (col < w_ - 2 && cdf(col + 1) <= tx) ++col;
  const double c0 = at(col, row) + (at(col, row + 1) - at(col, row)) * sy;
  const double c1 = at(col + 1, row) + (at(col + 1, row + 1) - at(col + 1, row)) * sy;
  const double sx = invert_linear_segment(tx - cdf(col), dx, c0, c1);
  return {(col + sx) * dx, (row + sy) * dy};
}

}  // namespace weft::rgl
