#pragma once
// Piecewise-constant 1-D and 2-D distributions over [0,1) and [0,1)^2 (pbrt's convention).
#include <cstddef>
#include <span>
#include <vector>

#include "weft/core/vec.h"

namespace weft {

class Distribution1D {
 public:
  Distribution1D() = default;
  // Non-negative weights, one per bin. All-zero input gives a uniform distribution flagged
  // by integral() == 0 so callers can tell.
  explicit Distribution1D(std::span<const double> weights);

  size_t size() const { return func_.size(); }
  double integral() const { return integral_; }  // mean of the weights over [0,1)
  double func(size_t i) const { return func_[i]; }

  struct Sample {
    double x;    // continuous position in [0, 1)
    double pdf;  // density w.r.t. x
    size_t bin;
  };
  Sample sample_continuous(double u) const;
  size_t sample_discrete(double u, double* pmf = nullptr) const;
  double pdf(double x) const;                     // density at x in [0,1)
  double pmf(size_t bin) const;                   // probability of a bin
  double cdf(size_t i) const { return cdf_[i]; }  // probability of bins [0, i), i <= size()
  size_t bin_of(double x) const;                  // the bin holding x (clamped to the range)

 private:
  std::vector<double> func_, cdf_;
  double integral_ = 0;
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // Row-major weights: nv rows of nu values (u is the fast axis).
  Distribution2D(std::span<const double> weights, size_t nu, size_t nv);

  struct Sample {
    Vec2 p;      // in [0,1)^2
    double pdf;  // density w.r.t. area in [0,1)^2
  };
  Sample sample(Vec2 u) const;
  double pdf(Vec2 p) const;
  double integral() const { return marginal_.integral(); }
  size_t nu() const { return nu_; }
  size_t nv() const { return nv_; }
  // The distribution of rows (v): marginal().cdf(k) is the probability of the rows below k, and
  // sample({u.x, u.y * marginal().cdf(k)}) samples the density restricted to them (it never
  // returns a row of zero probability).
  const Distribution1D& marginal() const { return marginal_; }

 private:
  size_t nu_ = 0, nv_ = 0;
  std::vector<Distribution1D> conditional_;
  Distribution1D marginal_;
};

}  // namespace weft
