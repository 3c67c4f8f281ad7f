#include "weft/fiber/phase_function.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"

namespace weft {

PhaseFunction PhaseFunction::henyey_greenstein(double g) {
  if (!(g > -1 && g < 1)) throw Error("", "g", "Henyey-Greenstein g must lie in (-1, 1)");
  PhaseFunction f;
  f.g_ = g;
  return f;
}

PhaseFunction PhaseFunction::tabulated(std::span<const double> mu, std::span<const double> p) {
  if (mu.size() < 2 || mu.size() != p.size())
    throw Error("", "phase_function", "needs >= 2 nodes and as many values as nodes");
  if (std::abs(mu.front() + 1) > 1e-12 || std::abs(mu.back() - 1) > 1e-12)
    throw Error("", "phase_function", "nodes must span mu = -1 .. 1");
  PhaseFunction f;
  f.mu_.assign(mu.begin(), mu.end());
  f.p_.assign(p.begin(), p.end());
  f.cdf_.assign(mu.size(), 0.0);
  for (size_t i = 0; i < mu.size(); ++i) {
    if (!std::isfinite(p[i]) || p[i] < 0)
      throw Error("", "phase_function",
                  "value " + std::to_string(i) + " is negative or not finite");
    if (i > 0) {
      if (!(mu[i] > mu[i - 1])) throw Error("", "phase_function", "nodes must increase strictly");
      f.cdf_[i] = f.cdf_[i - 1] + 0.5 * (p[i] + p[i - 1]) * (mu[i] - mu[i - 1]);
    }
  }
  const double total = f.cdf_.back();
  if (!(total > 0)) throw Error("", "phase_function", "phase function integrates to zero");
  for (auto& v : f.p_) v /= total;  // density in mu
  for (auto& v : f.cdf_) v /= total;
  return f;
}

double PhaseFunction::sample_cos_theta(double u) const {
  if (mu_.empty()) {
    if (std::abs(g_) < 1e-6) return 1 - 2 * u;
    // Inverse CDF of HG (Prahl's MCML form).
    const double s = (1 - g_ * g_) / (1 - g_ + 2 * g_ * u);
    return std::clamp((1 + g_ * g_ - s * s) / (2 * g_), -1.0, 1.0);
  }
  // Find the segment, then invert the CDF of a linear density on it exactly.
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  size_t i = static_cast<size_t>(std::clamp<std::ptrdiff_t>(
      (it - cdf_.begin()) - 1, 0, static_cast<std::ptrdiff_t>(mu_.size()) - 2));
  const double h = mu_[i + 1] - mu_[i];
  const double a = p_[i], b = p_[i + 1];
  const double target = u - cdf_[i];  // area to accumulate inside the segment
  // area(t) = h * (a t + (b - a) t^2 / 2), t in [0, 1].
  double t;
  const double slope = b - a;
  if (std::abs(slope) < 1e-12 * std::max(a, b)) {
    t = a > 0 ? target / (h * a) : 0.5;
  } else {
    const double disc = std::max(0.0, a * a + 2 * slope * target / h);
    t = (std::sqrt(disc) - a) / slope;
    // Stable form when a dominates: t = 2 target / (h (a + sqrt(disc))).
    if (a > 0) t = 2 * target / (h * (a + std::sqrt(disc)));
  }
  t = std::clamp(t, 0.0, 1.0);
  return std::clamp(mu_[i] + t * h, -1.0, 1.0);
}

Vec3 PhaseFunction::sample_direction(const Vec3& dir, double u1, double u2) const {
  const double cos_t = sample_cos_theta(u1);
  const double sin_t = safe_sqrt(1 - cos_t * cos_t);
  const double phi = 2 * kPi * u2;
  const Frame f = Frame::from_normal(dir);
  return normalize(f.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t}));
}

double PhaseFunction::eval(double cos_theta) const {
  if (mu_.empty()) {
    const double d = 1 + g_ * g_ - 2 * g_ * cos_theta;
    return kInv4Pi * (1 - g_ * g_) / (d * std::sqrt(d));
  }
  cos_theta = std::clamp(cos_theta, -1.0, 1.0);
  const auto it = std::upper_bound(mu_.begin(), mu_.end(), cos_theta);
  const size_t i = static_cast<size_t>(std::clamp<std::ptrdiff_t>(
      (it - mu_.begin()) - 1, 0, static_cast<std::ptrdiff_t>(mu_.size()) - 2));
  const double t = (cos_theta - mu_[i]) / (mu_[i + 1] - mu_[i]);
  // Density in mu spread uniformly in azimuth.
  return ((1 - t) * p_[i] + t * p_[i + 1]) / (2 * kPi);
}

double PhaseFunction::mean_cosine() const {
  if (mu_.empty()) return g_;
  // Exact integral of mu * (linear p) over each segment.
  double sum = 0;
  for (size_t i = 0; i + 1 < mu_.size(); ++i) {
    const double m0 = mu_[i], m1 = mu_[i + 1], p0 = p_[i], p1 = p_[i + 1];
    const double h = m1 - m0;
    sum += h * (p0 * (2 * m0 + m1) + p1 * (m0 + 2 * m1)) / 6;
  }
  return sum;
}

}  // namespace weft
