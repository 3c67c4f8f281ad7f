#pragma once
// Test helpers for BSDFs: a chi^2 goodness-of-fit test of sample() against pdf() in the style of
// Mitsuba 3's chi2.py (histogram on an odd-resolution grid, expected counts from the pdf
// integrated over each cell, pooling of cells with expected count < 5, Sidak-corrected
// significance), plus Monte Carlo albedo and pdf-integral helpers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"
#include "weft/materials/bsdfs.h"

namespace weft::testing {

// Regularized upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a): power series of P for
// x < a + 1, Lentz's continued fraction for Q otherwise.
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  const double log_prefactor = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1) {
    double term = 1 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return 1 - sum * std::exp(log_prefactor);
  }
  constexpr double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < 1e-15) break;
  }
  return std::exp(log_prefactor) * h;
}

// P(X >= statistic) for X ~ chi^2 with 'dof' degrees of freedom.
inline double chi2_survival(double statistic, int dof) {
  return gamma_q(0.5 * dof, 0.5 * statistic);
}

// Per-test significance so that 'tests' independent tests together reject a correct sampler with
// probability alpha (Sidak correction).
inline double sidak_significance(double alpha, int tests) {
  return 1 - std::pow(1 - alpha, 1.0 / tests);
}

struct Chi2Result {
  bool passed = false;
  double statistic = 0, p_value = 0;
  int dof = 0, pooled_cells = 0;
  std::string message;
};

// Pooled chi^2 test of observed against expected counts.
inline Chi2Result chi2_pooled(std::span<const double> observed, std::span<const double> expected,
                              double significance, double pool_threshold = 5) {
  Chi2Result r;
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  double pool_obs = 0, pool_exp = 0;
  for (size_t i : order) {
    if (expected[i] == 0 && observed[i] > 0) {
      r.message = "cell " + std::to_string(i) + " has " + std::to_string(observed[i]) +
                  " samples where the pdf integrates to 0";
      return r;
    }
    if (expected[i] < pool_threshold) {
      pool_obs += observed[i];
      pool_exp += expected[i];
      ++r.pooled_cells;
    } else {
      r.statistic += sqr(observed[i] - expected[i]) / expected[i];
      ++r.dof;
    }
  }
  if (pool_exp > 0) {
    r.statistic += sqr(pool_obs - pool_exp) / pool_exp;
    ++r.dof;
  } else if (pool_obs > 0) {
    r.message = "pooled cells hold samples but no expected mass";
    return r;
  }
  r.dof -= 1;
  if (r.dof < 1) {
    r.message = "too few cells for a chi^2 test";
    return r;
  }
  r.p_value = chi2_survival(r.statistic, r.dof);
  r.passed = r.p_value >= significance;
  std::ostringstream os;
  os << "chi^2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value
     << " (significance " << significance << "), pooled " << r.pooled_cells << " cells";
  r.message = os.str();
  return r;
}

// Draws one direction (or nothing) from its own random numbers.
using DirectionSampler = std::function<std::optional<Vec3>(Rng&)>;
using DirectionPdf = std::function<double(const Vec3&)>;

// (theta, phi) grid over the whole sphere: theta in [0, pi] with 2 * n_theta_half bins (the
// equator is a bin edge, so one-sided pdfs are never integrated across their discontinuity),
// phi in [-pi, pi] with n_phi bins; n_theta_half and n_phi are odd (Mitsuba's habit, which keeps
// symmetry planes such as phi = 0 off the bin edges).
struct SphericalGrid {
  int n_theta_half = 21, n_phi = 41;
  int subdivisions = 3;  // Gauss-Legendre (5 points) on subdivisions^2 pieces of each cell

  int cells() const { return 2 * n_theta_half * n_phi; }
  int cell_of(const Vec3& w) const {
    const double theta = safe_acos(w.z), phi = std::atan2(w.y, w.x);
    const int it =
        std::clamp(static_cast<int>(theta / kPi * 2 * n_theta_half), 0, 2 * n_theta_half - 1);
    const int ip = std::clamp(static_cast<int>((phi + kPi) / (2 * kPi) * n_phi), 0, n_phi - 1);
    return it * n_phi + ip;
  }
  // Integral of pdf over every cell (solid angle).
  std::vector<double> integrate(const DirectionPdf& pdf) const {
    static constexpr double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                    0.5384693101056831, 0.9061798459386640};
    static constexpr double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                    0.4786286704993665, 0.2369268850561891};
    const int nt = 2 * n_theta_half;
    const double dt = kPi / nt / subdivisions, dp = 2 * kPi / n_phi / subdivisions;
    std::vector<double> out(cells(), 0.0);
    for (int it = 0; it < nt; ++it)
      for (int ip = 0; ip < n_phi; ++ip) {
        double sum = 0;
        for (int st = 0; st < subdivisions; ++st)
          for (int sp = 0; sp < subdivisions; ++sp) {
            const double t0 = it * kPi / nt + st * dt, p0 = -kPi + ip * 2 * kPi / n_phi + sp * dp;
            for (int a = 0; a < 5; ++a)
              for (int b = 0; b < 5; ++b) {
                const double theta = t0 + 0.5 * dt * (x[a] + 1), phi = p0 + 0.5 * dp * (x[b] + 1);
                sum += w[a] * w[b] * pdf(spherical_direction(theta, phi)) * std::sin(theta);
              }
          }
        out[it * n_phi + ip] = sum * 0.25 * dt * dp;
      }
    return out;
  }
};

// n x n grid on the equal-area octahedral square (n odd), integrated by the midpoint rule on
// 'subdivisions'^2 pieces per cell. For a table of resolution R choose n * subdivisions a
// multiple of R: every piece then lies inside one table cell, where the table's pdf is constant,
// and the integral is exact.
struct OctahedralSquareGrid {
  int n = 17, subdivisions = 16;

  int cells() const { return n * n; }
  int cell_of(const Vec3& w) const {
    const Vec2 p = equal_area_sphere_to_square(w);
    const int x = std::clamp(static_cast<int>(p.x * n), 0, n - 1);
    const int y = std::clamp(static_cast<int>(p.y * n), 0, n - 1);
    return y * n + x;
  }
  std::vector<double> integrate(const DirectionPdf& pdf) const {
    std::vector<double> out(cells(), 0.0);
    const int m = n * subdivisions;
    const double area = 4 * kPi / (static_cast<double>(m) * m);  // solid angle of one piece
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const Vec3 w = equal_area_square_to_sphere({(i + 0.5) / m, (j + 0.5) / m});
        out[(j / subdivisions) * n + i / subdivisions] += pdf(w) * area;
      }
    return out;
  }
};

// The tables' DirectionGrid at 'resolution' bins per hemisphere side, integrated by the midpoint
// rule on 'subdivisions'^2 pieces per cell. A table of resolution R has a pdf constant on its own
// cells: with resolution a multiple of R the integral is exact.
struct DirectionGridBins {
  int resolution = 8, subdivisions = 8;

  int cells() const { return DirectionGrid{resolution}.bins(); }
  int cell_of(const Vec3& w) const { return DirectionGrid{resolution}.bin_of(w); }
  std::vector<double> integrate(const DirectionPdf& pdf) const {
    const DirectionGrid g{resolution};
    std::vector<double> out(cells(), 0.0);
    const int m = subdivisions;
    const double piece = g.bin_solid_angle() / (static_cast<double>(m) * m);
    for (int b = 0; b < g.bins(); ++b)
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i)
          out[b] +=
              pdf(DirectionGrid::to_direction(g.chart_point(b, (i + 0.5) / m, (j + 0.5) / m))) *
              piece;
    return out;
  }
};

template <class Grid>
Chi2Result chi2_test(const DirectionSampler& sample, const DirectionPdf& pdf, const Grid& grid,
                     int count, double significance, uint64_t seed) {
  std::vector<double> observed(grid.cells(), 0.0);
  Rng rng(seed);
  for (int i = 0; i < count; ++i) {
    const auto w = sample(rng);
    if (!w) continue;
    if (!is_finite(*w) || std::abs(length(*w) - 1) > 1e-6) {
      Chi2Result r;
      r.message = "sample() returned a non-unit or non-finite direction";
      return r;
    }
    observed[grid.cell_of(*w)] += 1;
  }
  std::vector<double> expected = grid.integrate(pdf);
  for (double& e : expected) e *= count;
  return chi2_pooled(observed, expected, significance);
}

// Adapters for a Bsdf at a fixed wo.
inline DirectionSampler bsdf_sampler(const Bsdf& bsdf, const Vec3& wo) {
  return [bsdf, wo](Rng& rng) -> std::optional<Vec3> {
    const Vec2 u{rng.uniform(), rng.uniform()};
    const auto s = bsdf.sample(wo, u, rng.uniform());
    if (!s) return std::nullopt;
    return s->wi;
  };
}
inline DirectionPdf bsdf_pdf(const Bsdf& bsdf, const Vec3& wo) {
  return [bsdf, wo](const Vec3& wi) { return bsdf.pdf(wo, wi); };
}

// Monte Carlo directional albedo int f |cos| dwi from sample weights: mean and standard error.
struct AlbedoEstimate {
  Rgb mean, standard_error;
};
inline AlbedoEstimate estimate_albedo(const Bsdf& bsdf, const Vec3& wo, int count, uint64_t seed) {
  Rng rng(seed);
  Rgb s, s2;
  for (int i = 0; i < count; ++i) {
    const Vec2 u{rng.uniform(), rng.uniform()};
    const auto smp = bsdf.sample(wo, u, rng.uniform());
    if (!smp) continue;
    s += smp->weight;
    s2 += smp->weight * smp->weight;
  }
  AlbedoEstimate e;
  e.mean = s / count;
  const Rgb var = s2 / count + Rgb(-1.0) * e.mean * e.mean;
  e.standard_error = {std::sqrt(std::max(0.0, var.r) / count),
                      std::sqrt(std::max(0.0, var.g) / count),
                      std::sqrt(std::max(0.0, var.b) / count)};
  return e;
}

// Direction at polar angle theta (radians) and azimuth phi, on the upper side.
inline Vec3 direction(double theta, double phi = 0.3) {
  return spherical_direction(theta, phi);
}

}  // namespace weft::testing
