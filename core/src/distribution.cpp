#include "weft/core/distribution.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"

namespace weft {

Distribution1D::Distribution1D(std::span<const double> weights)
    : func_(weights.begin(), weights.end()), cdf_(weights.size() + 1) {
  if (func_.empty()) throw Error("Distribution1D: no bins");
  const double n = static_cast<double>(func_.size());
  cdf_[0] = 0;
  for (size_t i = 0; i < func_.size(); ++i) {
    if (!(func_[i] >= 0) || !std::isfinite(func_[i]))
      throw Error("Distribution1D: weight " + std::to_string(i) + " is negative or not finite");
    cdf_[i + 1] = cdf_[i] + func_[i] / n;
  }
  integral_ = cdf_.back();
  if (integral_ == 0) {
    for (size_t i = 1; i < cdf_.size(); ++i) cdf_[i] = static_cast<double>(i) / n;
  } else {
    for (size_t i = 1; i < cdf_.size(); ++i) cdf_[i] /= integral_;
  }
  cdf_.back() = 1.0;
}

size_t Distribution1D::sample_discrete(double u, double* pmf_out) const {
  // Largest index i with cdf[i] <= u, restricted to bins of non-zero probability.
  auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  size_t i = static_cast<size_t>(std::max<std::ptrdiff_t>(0, (it - cdf_.begin()) - 1));
  i = std::min(i, func_.size() - 1);
  while (i + 1 < func_.size() && cdf_[i + 1] - cdf_[i] <= 0) ++i;
  while (i > 0 && cdf_[i + 1] - cdf_[i] <= 0) --i;
  if (pmf_out) *pmf_out = cdf_[i + 1] - cdf_[i];
  return i;
}

Distribution1D::Sample Distribution1D::sample_continuous(double u) const {
  double p = 0;
  const size_t i = sample_discrete(u, &p);
  double du = (u - cdf_[i]) / p;
  du = std::clamp(du, 0.0, 1.0);
  const double n = static_cast<double>(func_.size());
  double x = (static_cast<double>(i) + du) / n;
  if (x >= 1.0) x = std::nextafter(1.0, 0.0);
  return {x, p * n, i};
}

size_t Distribution1D::bin_of(double x) const {
  const double n = static_cast<double>(func_.size());
  const auto i = static_cast<long long>(std::floor(x * n));
  return static_cast<size_t>(std::clamp<long long>(i, 0, static_cast<long long>(func_.size()) - 1));
}

double Distribution1D::pmf(size_t bin) const {
  return cdf_[bin + 1] - cdf_[bin];
}

double Distribution1D::pdf(double x) const {
  return pmf(bin_of(x)) * static_cast<double>(func_.size());
}

Distribution2D::Distribution2D(std::span<const double> weights, size_t nu, size_t nv)
    : nu_(nu), nv_(nv) {
  if (nu == 0 || nv == 0 || weights.size() != nu * nv)
    throw Error("Distribution2D: weights size does not match nu * nv");
  conditional_.reserve(nv);
  std::vector<double> marginal(nv);
  for (size_t v = 0; v < nv; ++v) {
    conditional_.emplace_back(weights.subspan(v * nu, nu));
    marginal[v] = conditional_.back().integral();
  }
  marginal_ = Distribution1D(marginal);
}

Distribution2D::Sample Distribution2D::sample(Vec2 u) const {
  const auto mv = marginal_.sample_continuous(u.y);
  const auto cu = conditional_[mv.bin].sample_continuous(u.x);
  return {{cu.x, mv.x}, cu.pdf * mv.pdf};
}

double Distribution2D::pdf(Vec2 p) const {
  const size_t v = marginal_.bin_of(p.y);
  return marginal_.pdf(p.y) * conditional_[v].pdf(p.x);
}

}  // namespace weft
