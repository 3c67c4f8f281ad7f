#include "weft/core/optimize.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "weft/core/error.h"

namespace weft {
namespace {

using Matrix = std::vector<std::vector<double>>;

double sum_squares(const std::vector<double>& r) {
  double s = 0;
  for (double x : r) s += x * x;
  return s;
}

std::vector<double> clamped(std::vector<double> u) {
  for (double& x : u) x = std::clamp(x, 0.0, 1.0);
  return u;
}

// A step from u along an axis that stays in the cube: +step, or -step where that would leave it.
double step_inside(double u, double step) {
  return u + step <= 1 ? step : -step;
}

// The residual function and how often it has been evaluated.
struct CountedResiduals {
  const ResidualFunction& residuals;
  int evaluations = 0;
  std::vector<double> operator()(const std::vector<double>& u) {
    ++evaluations;
    return residuals(u);
  }
};

void check_search(const std::vector<double>& u0, const OptimizeOptions& o) {
  o.validate();
  if (u0.empty()) throw Error("", "u0", "a search needs at least one coordinate");
  for (double x : u0)
    if (!(x >= 0 && x <= 1)) throw Error("", "u0", "the start must lie in the unit cube");
}

// J^T J of a Jacobian stored by coordinate (jac[k][i] = d r_i / d u_k).
Matrix normal_matrix(const Matrix& jac) {
  const size_t n = jac.size();
  Matrix a(n, std::vector<double>(n, 0.0));
  for (size_t p = 0; p < n; ++p)
    for (size_t q = 0; q < n; ++q)
      for (size_t i = 0; i < jac[p].size(); ++i) a[p][q] += jac[p][i] * jac[q][i];
  return a;
}

// ---- Nelder-Mead ----------------------------------------------------------------------------

struct Simplex {
  Matrix points;          // n + 1, sorted by 'f' between steps
  std::vector<double> f;  // the RMS at each point
};

// Sorts the points by their RMS, best first (ties keep their order).
void sort_simplex(Simplex& s) {
  const size_t count = s.points.size();
  std::vector<size_t> order(count);
  for (size_t k = 0; k < count; ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return s.f[a] < s.f[b]; });
  Simplex sorted;
  for (size_t k : order) {
    sorted.points.push_back(s.points[k]);
    sorted.f.push_back(s.f[k]);
  }
  s = std::move(sorted);
}

// A sorted simplex has converged when its values span less than the tolerance and its edges from
// the best point are below 1e-3.
bool simplex_converged(const Simplex& s, double tolerance) {
  const size_t n = s.points.size() - 1;
  double size = 0;
  for (size_t k = 1; k <= n; ++k)
    for (size_t d = 0; d < n; ++d) size = std::max(size, std::abs(s.points[k][d] - s.points[0][d]));
  return s.f[n] - s.f[0] < tolerance && size < 1e-3;
}

// One step on a sorted simplex: the worst point reflected through the centroid of the others,
// then expanded, contracted, or the simplex shrunk towards the best point.
void nelder_mead_step(Simplex& s, CountedResiduals& eval) {
  const size_t n = s.points.size() - 1;
  auto& simplex = s.points;
  auto& f = s.f;
  std::vector<double> centroid(n, 0.0);
  for (size_t k = 0; k < n; ++k)
    for (size_t d = 0; d < n; ++d) centroid[d] += simplex[k][d] / static_cast<double>(n);
  auto along = [&](double t) {
    std::vector<double> u(n);
    for (size_t d = 0; d < n; ++d) u[d] = centroid[d] + t * (simplex[n][d] - centroid[d]);
    return clamped(u);
  };
  const auto ur = along(-1.0);
  const double fr = residual_rms(eval(ur));
  if (fr < f[0]) {
    const auto ue = along(-2.0);
    const double fe = residual_rms(eval(ue));
    if (fe < fr) {
      simplex[n] = ue;
      f[n] = fe;
    } else {
      simplex[n] = ur;
      f[n] = fr;
    }
  } else if (fr < f[n - 1]) {
    simplex[n] = ur;
    f[n] = fr;
  } else {
    const bool outside = fr < f[n];
    const auto uc = along(outside ? -0.5 : 0.5);
    const double fc = residual_rms(eval(uc));
    if (fc < (outside ? fr : f[n])) {
      simplex[n] = uc;
      f[n] = fc;
    } else {  // shrink towards the best point
      for (size_t k = 1; k <= n; ++k) {
        for (size_t d = 0; d < n; ++d)
          simplex[k][d] = simplex[0][d] + 0.5 * (simplex[k][d] - simplex[0][d]);
        f[k] = residual_rms(eval(simplex[k]));
      }
    }
  }
}

// ---- Levenberg-Marquardt --------------------------------------------------------------------

// The search's state between Jacobians.
struct LmState {
  std::vector<double> u, r;  // the current point and its residuals
  double ssr = 0;            // their sum of squares
  double lambda = -1, nu = 2;
};

// J by one-sided differences towards the cube's inside: n evaluations.
Matrix forward_jacobian(CountedResiduals& eval, const LmState& st, double step) {
  const size_t n = st.u.size(), m = st.r.size();
  Matrix jac(n, std::vector<double>(m));
  for (size_t k = 0; k < n; ++k) {
    auto up = st.u;
    const double h = step_inside(st.u[k], step);
    up[k] += h;
    const std::vector<double> rp = eval(up);
    for (size_t i = 0; i < m; ++i) jac[k][i] = (rp[i] - st.r[i]) / h;
  }
  return jac;
}

// J^T r: half the gradient of the SSR.
std::vector<double> half_gradient(const Matrix& jac, const std::vector<double>& r) {
  std::vector<double> g(jac.size(), 0.0);
  for (size_t p = 0; p < jac.size(); ++p)
    for (size_t i = 0; i < r.size(); ++i) g[p] += jac[p][i] * r[i];
  return g;
}

// The damped Gauss-Newton step from u, projected into the cube, with the coordinates at a bound
// whose gradient points outside held; false when none is free or the damped system is singular.
bool damped_step(const Matrix& a, const std::vector<double>& g, const std::vector<double>& u,
                 double lambda, double diag_max, std::vector<double>& s) {
  const size_t n = u.size();
  std::vector<size_t> free;
  for (size_t k = 0; k < n; ++k)
    if (!((u[k] <= 0 && g[k] > 0) || (u[k] >= 1 && g[k] < 0))) free.push_back(k);
  s.assign(n, 0.0);
  if (free.empty()) return false;
  Matrix b(free.size(), std::vector<double>(free.size()));
  for (size_t p = 0; p < free.size(); ++p)
    for (size_t q = 0; q < free.size(); ++q)
      b[p][q] = a[free[p]][free[q]] +
                (p == q ? lambda * std::max(a[free[p]][free[p]], 1e-9 * diag_max) : 0.0);
  if (!invert_matrix(b)) return false;
  std::vector<double> un = u;
  for (size_t p = 0; p < free.size(); ++p) {
    double d = 0;
    for (size_t q = 0; q < free.size(); ++q) d -= b[p][q] * g[free[q]];
    un[free[p]] += d;
  }
  un = clamped(un);
  for (size_t k = 0; k < n; ++k) s[k] = un[k] - u[k];
  return true;
}

// The linear model's decrease of the SSR along the (projected) step: -(2 g.s + s.A s).
double predicted_decrease(const Matrix& a, const std::vector<double>& g,
                          const std::vector<double>& s) {
  double predicted = 0;
  for (size_t p = 0; p < s.size(); ++p) {
    predicted -= 2 * g[p] * s[p];
    for (size_t q = 0; q < s.size(); ++q) predicted -= s[p] * a[p][q] * s[q];
  }
  return predicted;
}

enum class LmOutcome { kStepped, kConverged, kOutOfBudget };

// Steps at one Jacobian, the damping growing after each that does not lower the SSR, until one
// does (kStepped, or kConverged when it lowered the RMS by less than the tolerance and predicted
// no more), no step of more than 1e-3 is left to try (kConverged: the damping has shrunk it to
// nothing, no descent at this scale), or the evaluations are spent.
LmOutcome lm_steps(CountedResiduals& eval, const OptimizeOptions& o, const Matrix& a,
                   const std::vector<double>& g, double diag_max, double count, LmState& st) {
  const size_t n = st.u.size();
  for (;;) {
    std::vector<double> s;
    const bool solved = damped_step(a, g, st.u, st.lambda, diag_max, s);
    double longest = 0;
    for (double x : s) longest = std::max(longest, std::abs(x));
    if (!solved || longest < 1e-3) return LmOutcome::kConverged;
    if (eval.evaluations + 1 > o.max_evaluations) return LmOutcome::kOutOfBudget;
    const double predicted = predicted_decrease(a, g, s);
    std::vector<double> un = st.u;
    for (size_t k = 0; k < n; ++k) un[k] += s[k];
    std::vector<double> rn = eval(un);
    const double ssr_new = sum_squares(rn);
    if (ssr_new < st.ssr) {
      const double rho = predicted > 0 ? (st.ssr - ssr_new) / predicted : 0.0;
      const double drop = std::sqrt(st.ssr / count) - std::sqrt(ssr_new / count);
      const double drop_predicted =
          std::sqrt(st.ssr / count) - std::sqrt(std::max(0.0, st.ssr - predicted) / count);
      st.u = un;
      st.r = std::move(rn);
      st.ssr = ssr_new;
      st.lambda *= std::max(1.0 / 3.0, 1 - std::pow(2 * rho - 1, 3));
      st.nu = 2;
      const bool converged = drop < o.tolerance && drop_predicted < o.tolerance;
      return converged ? LmOutcome::kConverged : LmOutcome::kStepped;
    }
    st.lambda *= st.nu;
    st.nu *= 2;
  }
}

}  // namespace

double residual_rms(const std::vector<double>& r) {
  return r.empty() ? 0.0 : std::sqrt(sum_squares(r) / static_cast<double>(r.size()));
}

void OptimizeOptions::validate() const {
  if (max_evaluations < 0) throw Error("", "max_evaluations", "must be >= 0");
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    throw Error("", "tolerance", "must be a positive number");
  if (!(initial_step > 0 && initial_step <= 0.5))
    throw Error("", "initial_step", "must lie in (0, 0.5]");
  if (!(jacobian_step > 0 && jacobian_step <= 0.25))
    throw Error("", "jacobian_step", "must lie in (0, 0.25]");
}

OptimizeResult nelder_mead(const ResidualFunction& residuals, const std::vector<double>& u0,
                           const OptimizeOptions& o, const std::function<void()>& at_start) {
  check_search(u0, o);
  const size_t n = u0.size();
  CountedResiduals eval{residuals};
  Simplex s;
  s.points.push_back(u0);
  for (size_t k = 0; k < n; ++k) {
    auto u = u0;
    u[k] += step_inside(u[k], o.initial_step);
    s.points.push_back(u);
  }
  for (const auto& u : s.points) {
    s.f.push_back(residual_rms(eval(u)));
    if (s.f.size() == 1 && at_start) at_start();
  }
  OptimizeResult out;
  out.objective_start = s.f[0];
  while (eval.evaluations < o.max_evaluations) {
    sort_simplex(s);
    if (simplex_converged(s, o.tolerance)) {
      out.converged = true;
      break;
    }
    nelder_mead_step(s, eval);
  }
  size_t best = 0;
  for (size_t k = 1; k <= n; ++k)
    if (s.f[k] < s.f[best]) best = k;
  out.u = s.points[best];
  out.objective = s.f[best];
  out.evaluations = eval.evaluations;
  return out;
}

OptimizeResult levenberg_marquardt(const ResidualFunction& residuals, const std::vector<double>& u0,
                                   const OptimizeOptions& o,
                                   const std::function<void()>& at_start) {
  check_search(u0, o);
  const size_t n = u0.size();
  CountedResiduals eval{residuals};
  LmState st;
  st.u = u0;
  st.r = eval(u0);
  if (at_start) at_start();
  const double count = static_cast<double>(std::max<size_t>(st.r.size(), 1));
  st.ssr = sum_squares(st.r);
  OptimizeResult out;
  out.objective_start = std::sqrt(st.ssr / count);
  while (eval.evaluations + static_cast<int>(n) + 1 <= o.max_evaluations) {
    const Matrix jac = forward_jacobian(eval, st, o.jacobian_step);
    const Matrix a = normal_matrix(jac);
    const std::vector<double> g = half_gradient(jac, st.r);
    double diag_max = 0;
    for (size_t k = 0; k < n; ++k) diag_max = std::max(diag_max, a[k][k]);
    if (!(diag_max > 0)) {  // the residuals do not move: nothing to descend
      out.converged = true;
      break;
    }
    if (st.lambda < 0) st.lambda = 1e-3 * diag_max;
    const LmOutcome outcome = lm_steps(eval, o, a, g, diag_max, count, st);
    if (outcome == LmOutcome::kConverged) out.converged = true;
    if (outcome != LmOutcome::kStepped) break;
  }
  out.u = st.u;
  out.objective = std::sqrt(st.ssr / count);
  out.evaluations = eval.evaluations;
  return out;
}

bool invert_matrix(std::vector<std::vector<double>>& a) {
  const size_t n = a.size();
  Matrix inv(n, std::vector<double>(n, 0.0));
  for (size_t i = 0; i < n; ++i) inv[i][i] = 1;
  double scale = 0;
  for (const auto& row : a)
    for (double x : row) scale = std::max(scale, std::abs(x));
  for (size_t c = 0; c < n; ++c) {
    size_t piv = c;
    for (size_t r = c + 1; r < n; ++r)
      if (std::abs(a[r][c]) > std::abs(a[piv][c])) piv = r;
    if (!(std::abs(a[piv][c]) > 1e-12 * scale)) return false;
    std::swap(a[piv], a[c]);
    std::swap(inv[piv], inv[c]);
    const double d = a[c][c];
    for (size_t k = 0; k < n; ++k) {
      a[c][k] /= d;
      inv[c][k] /= d;
    }
    for (size_t r = 0; r < n; ++r) {
      if (r == c) continue;
      const double f = a[r][c];
      for (size_t k = 0; k < n; ++k) {
        a[r][k] -= f * a[c][k];
        inv[r][k] -= f * inv[c][k];
      }
    }
  }
  a = inv;
  return true;
}

double GaussNewtonCovariance::sigma(size_t k) const {
  return determined && jtj_inverse[k][k] > 0 ? std::sqrt(s2 * jtj_inverse[k][k]) : std::nan("");
}

GaussNewtonCovariance gauss_newton_covariance(const ResidualFunction& residuals,
                                              const std::vector<double>& u,
                                              const std::vector<double>& r, double jacobian_step) {
  const size_t n = u.size(), m = r.size();
  Matrix jac(n);
  for (size_t k = 0; k < n; ++k) {
    auto up = u, dn = u;
    up[k] = std::min(1.0, u[k] + jacobian_step);
    dn[k] = std::max(0.0, u[k] - jacobian_step);
    const auto rp = residuals(up), rm = residuals(dn);
    jac[k].resize(m);
    for (size_t i = 0; i < m; ++i) jac[k][i] = (rp[i] - rm[i]) / (up[k] - dn[k]);
  }
  GaussNewtonCovariance c;
  c.jtj_inverse = normal_matrix(jac);
  const double ssr = sum_squares(r);
  c.s2 = m > n ? ssr / static_cast<double>(m - n) : std::nan("");
  c.determined = invert_matrix(c.jtj_inverse);
  return c;
}

}  // namespace weft
