#pragma once
// Bounded least squares in the unit cube: minimize the RMS of a residual vector r(u) over
// u in [0, 1]^n, by Nelder-Mead (no derivatives) or Levenberg-Marquardt (Gauss-Newton steps from a
// finite-difference Jacobian), and the Gauss-Newton covariance s^2 (J^T J)^-1 at an optimum. The
// caller maps its parameters' boxes onto the cube, so every point evaluated is a valid parameter
// set. Deterministic: the same function gives the same evaluations in the same order.
#include <cstddef>
#include <functional>
#include <vector>

namespace weft {

// The residuals at a point u of the unit cube; every call returns a vector of the same length.
using ResidualFunction = std::function<std::vector<double>(const std::vector<double>& u)>;

// The root mean square of residuals (0 for none): the objective every search here minimizes.
double residual_rms(const std::vector<double>& r);

struct OptimizeOptions {
  // Evaluations of the residuals during a search. Levenberg-Marquardt stays within it;
  // Nelder-Mead evaluates its whole start simplex (n + 1 points) and finishes the step it is in
  // (a shrink evaluates n points after its reflection and contraction), so it may end up to
  // n + 1 evaluations past it.
  int max_evaluations = 100;
  // Converged: Nelder-Mead when the simplex's RMS values span less than this and its edges are
  // below 1e-3 of the cube's side; Levenberg-Marquardt when a step lowers the RMS by less than
  // this and its linear model predicted no more, or when no step longer than 1e-3 lowers it.
  double tolerance = 1e-4;
  double initial_step = 0.15;  // Nelder-Mead's simplex edge, in (0, 0.5]
  // Finite differences, in (0, 0.25]: Levenberg-Marquardt's one-sided Jacobians, and the central
  // differences of gauss_newton_covariance.
  double jacobian_step = 0.02;
  void validate() const;  // weft::Error naming the field
};

struct OptimizeResult {
  std::vector<double> u;                      // the best point found
  double objective_start = 0, objective = 0;  // RMS of the residuals at the start and at u
  int evaluations = 0;
  bool converged = false;  // the tolerance was met before max_evaluations
};

// Nelder-Mead (standard coefficients 1, 2, 0.5, 0.5) on the RMS of the residuals, from a simplex
// of u0 and a step of initial_step along each axis (towards the cube's inside); points are
// projected into the cube. 'at_start' (optional) runs right after the evaluation of u0, so the
// caller can keep what its function computed there. weft::Error on an empty u0, a u0 outside the
// cube or bad options.
OptimizeResult nelder_mead(const ResidualFunction& residuals, const std::vector<double>& u0,
                           const OptimizeOptions& options,
                           const std::function<void()>& at_start = nullptr);

// Levenberg-Marquardt on the residuals (Marquardt's scaling by diag(J^T J), Nielsen's update of
// the damping). The Jacobian is by one-sided differences towards the cube's inside (n
// evaluations); a step is projected into the cube, and a coordinate at its bound whose gradient
// points outside is held there. 'at_start' and the errors as nelder_mead's.
OptimizeResult levenberg_marquardt(const ResidualFunction& residuals, const std::vector<double>& u0,
                                   const OptimizeOptions& options,
                                   const std::function<void()>& at_start = nullptr);

// Inverts a small square matrix in place by Gauss-Jordan elimination with partial pivoting; false
// (and 'a' overwritten) when a pivot is below 1e-12 of the largest entry: singular.
bool invert_matrix(std::vector<std::vector<double>>& a);

// The Gauss-Newton covariance of the optimum u of a least-squares fit: s^2 (J^T J)^-1, with J by
// central differences of step jacobian_step (clipped at the cube's bounds, where the difference
// becomes one-sided) and s^2 = SSR / (m - n) for m residuals. Treats the residuals as independent.
struct GaussNewtonCovariance {
  std::vector<std::vector<double>> jtj_inverse;  // (J^T J)^-1; meaningless unless 'determined'
  double s2 = 0;                                 // NaN when m <= n
  bool determined = false;                       // J^T J could be inverted
  // The standard deviation of coordinate k, sqrt(s^2 (J^T J)^-1_kk); NaN where J does not
  // determine it.
  double sigma(size_t k) const;
};

// 'r' is residuals(u), which the caller has; this evaluates residuals 2 n more times, in the order
// u + h e_0, u - h e_0, u + h e_1, ...
GaussNewtonCovariance gauss_newton_covariance(const ResidualFunction& residuals,
                                              const std::vector<double>& u,
                                              const std::vector<double>& r, double jacobian_step);

}  // namespace weft
