#pragma once
// The warp of the RGL format's 2-D distributions (Dupuy & Jakob 2018): a density given at the
// vertices of a regular w x h grid over [0,1]^2 and bilinear between them, sampled by inverting
// its continuous marginal CDF in y (piecewise quadratic, the row integrals being linear in y) and
// then the conditional CDF in x at that y. The renderers invert this same map to find where a
// direction lies in the sample space of the luminance / spectra tensors, so the writer samples it
// at those tensors' grid points. Written from the mathematics of the format, in double precision.
#include <vector>

#include "weft/core/vec.h"

namespace weft::rgl {

class MarginalWarp {
 public:
  // density: h rows of w values (row y, column x), >= 0 and not all 0; w, h >= 2.
  MarginalWarp(std::vector<double> density, int width, int height);
  // The point of [0,1]^2 that the uniform sample u in [0,1]^2 maps to.
  Vec2 sample(Vec2 u) const;

 private:
  std::vector<double> v_;         // the density
  std::vector<double> cond_;      // per row: its integral over x up to each vertex (w values)
  std::vector<double> marginal_;  // the integral over y up to each row (h values)
  int w_, h_;
  double at(int x, int y) const { return v_[static_cast<size_t>(y * w_ + x)]; }
  double cond(int x, int y) const { return cond_[static_cast<size_t>(y * w_ + x)]; }
};

// The s in [0, 1] at which the integral over [0, s] of the linear density a + (b - a) t, times
// 'width', reaches 'target' (0 <= target <= width (a + b) / 2).
double invert_linear_segment(double target, double width, double a, double b);

}  // namespace weft::rgl
