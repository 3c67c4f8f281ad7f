// Bounded least squares in the unit cube (core/optimize.h) on problems whose answers are published
// or follow in closed form: Rosenbrock's valley, a straight-line fit with its textbook estimates
// and covariance, an optimum on the box's edge; and the budget, the start hook and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.h"
#include "weft/core/optimize.h"

using weft::testing::error_of;

namespace weft {
namespace {

// Rosenbrock's function f = (1 - x)^2 + 100 (y - x^2)^2 as the residuals (1 - x, 10 (y - x^2)) on
// the box x, y in [-2, 2] (u = (x + 2) / 4). From the start (-1.2, 1), where f = 24.2, its minimum
// is f = 0 at (1, 1): H. H. Rosenbrock, The Computer Journal 3 (1960) 175-184; problem 1 of
// J. J. More, B. S. Garbow, K. E. Hillstrom, "Testing unconstrained optimization software", ACM
// Transactions on Mathematical Software 7 (1981) 17-41.
std::vector<double> rosenbrock(const std::vector<double>& u) {
  const double x = -2 + 4 * u[0], y = -2 + 4 * u[1];
  return {1 - x, 10 * (y - x * x)};
}
const std::vector<double> kRosenbrockStart = {(-1.2 + 2) / 4, (1.0 + 2) / 4};

TEST(Optimize, LevenbergMarquardtFindsRosenbrocksMinimum) {
  OptimizeOptions o;
  o.max_evaluations = 1000;
  o.tolerance = 1e-12;
  o.jacobian_step = 1e-7;
  const OptimizeResult r = levenberg_marquardt(rosenbrock, kRosenbrockStart, o);
  EXPECT_NEAR(r.objective_start, std::sqrt(24.2 / 2), 1e-12);  // RMS of two residuals
  EXPECT_TRUE(r.converged);
  // It stops once no step longer than 1e-3 of the cube lowers the objective (OptimizeOptions),
  // so it lands within about that of the minimum: 4e-3 in x and y.
  EXPECT_NEAR(-2 + 4 * r.u[0], 1.0, 4e-3);
  EXPECT_NEAR(-2 + 4 * r.u[1], 1.0, 4e-3);
  EXPECT_LT(r.objective, 1e-3);
  EXPECT_LE(r.evaluations, o.max_evaluations);
}

TEST(Optimize, NelderMeadFindsRosenbrocksMinimum) {
  OptimizeOptions o;
  o.max_evaluations = 2000;
  o.tolerance = 1e-10;
  const OptimizeResult r = nelder_mead(rosenbrock, kRosenbrockStart, o);
  EXPECT_NEAR(r.objective_start, std::sqrt(24.2 / 2), 1e-12);
  EXPECT_TRUE(r.converged);
  // Converged: the simplex's edges are below 1e-3 of the cube, 4e-3 in x and y.
  EXPECT_NEAR(-2 + 4 * r.u[0], 1.0, 4e-3);
  EXPECT_NEAR(-2 + 4 * r.u[1], 1.0, 8e-3);
  EXPECT_LT(r.objective, 1e-3);
}

// A straight line y = a + b t through five points, a and b in [-5, 5] (u = (x + 5) / 10). The
// least-squares estimates and their covariance in closed form (any regression text, e.g. N. R.
// Draper, H. Smith, "Applied Regression Analysis", 3rd ed., Wiley 1998, sections 1.2 and 3.2):
// b = Sty / Stt, a = ybar - b tbar; s^2 = SSR / (n - 2); Var b = s^2 / Stt,
// Var a = s^2 (1 / n + tbar^2 / Stt), Cov(a, b) = -s^2 tbar / Stt.
TEST(Optimize, StraightLineGivesTheLeastSquaresEstimatesAndTheirCovariance) {
  const std::vector<double> t = {0, 1, 2, 3, 4}, y = {0.9, 3.1, 4.8, 7.2, 8.9};
  const ResidualFunction line = [&](const std::vector<double>& u) {
    const double a = -5 + 10 * u[0], b = -5 + 10 * u[1];
    std::vector<double> r;
    for (size_t i = 0; i < t.size(); ++i) r.push_back(a + b * t[i] - y[i]);
    return r;
  };
  const double n = 5, tbar = 2, ybar = (0.9 + 3.1 + 4.8 + 7.2 + 8.9) / 5;
  double stt = 0, sty = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    stt += (t[i] - tbar) * (t[i] - tbar);
    sty += (t[i] - tbar) * (y[i] - ybar);
  }
  const double b = sty / stt, a = ybar - b * tbar;
  double ssr = 0;
  for (size_t i = 0; i < t.size(); ++i) ssr += (a + b * t[i] - y[i]) * (a + b * t[i] - y[i]);
  const double s2 = ssr / (n - 2);

  OptimizeOptions o;
  o.tolerance = 1e-12;
  const OptimizeResult r = levenberg_marquardt(line, {0.5, 0.5}, o);
  EXPECT_TRUE(r.converged);
  // Within 1e-3 of the cube (where it stops, as above): 1e-2 in a and b.
  EXPECT_NEAR(-5 + 10 * r.u[0], a, 1e-2);
  EXPECT_NEAR(-5 + 10 * r.u[1], b, 1e-2);
  EXPECT_GE(r.objective, std::sqrt(ssr / n) - 1e-12);  // nothing beats the least squares
  EXPECT_LT(r.objective, std::sqrt(ssr / n) + 1e-4);

  // At the least-squares point. In the cube the Jacobian is 10 times the design matrix, so
  // sigma(x) = 10 sigma(u); central differences of a linear function are exact.
  const std::vector<double> best = {(a + 5) / 10, (b + 5) / 10};
  const GaussNewtonCovariance c = gauss_newton_covariance(line, best, line(best), 0.02);
  ASSERT_TRUE(c.determined);
  EXPECT_NEAR(c.s2, s2, 1e-10);
  EXPECT_NEAR(10 * c.sigma(1), std::sqrt(s2 / stt), 1e-8);
  EXPECT_NEAR(10 * c.sigma(0), std::sqrt(s2 * (1 / n + tbar * tbar / stt)), 1e-8);
  EXPECT_NEAR(100 * c.s2 * c.jtj_inverse[0][1], -s2 * tbar / stt, 1e-8);
}

// The residuals (u0 + 0.5, u1 - 0.3): the unconstrained minimum (-0.5, 0.3) lies outside the
// cube; the sum of squares is separable, so the minimum over the cube is its projection (0, 0.3).
std::vector<double> beyond_the_edge(const std::vector<double>& u) {
  return {u[0] + 0.5, u[1] - 0.3};
}

TEST(Optimize, OptimumOnTheBoxEdge) {
  OptimizeOptions o;
  o.tolerance = 1e-12;
  const OptimizeResult lm = levenberg_marquardt(beyond_the_edge, {0.6, 0.6}, o);
  EXPECT_TRUE(lm.converged);
  EXPECT_EQ(lm.u[0], 0.0);  // held at the bound, its gradient pointing outside
  EXPECT_NEAR(lm.u[1], 0.3, 1e-3);
  EXPECT_NEAR(lm.objective, std::sqrt(0.25 / 2), 1e-6);
  o.max_evaluations = 500;
  const OptimizeResult nm = nelder_mead(beyond_the_edge, {0.6, 0.6}, o);
  EXPECT_TRUE(nm.converged);
  EXPECT_GE(nm.u[0], 0.0);  // every point is projected into the cube
  EXPECT_LT(nm.u[0], 1e-3);
  EXPECT_NEAR(nm.u[1], 0.3, 1e-3);
}

TEST(Optimize, EvaluationBudgetIsRespected) {
  for (int budget : {4, 7, 12}) {
    OptimizeOptions o;
    o.max_evaluations = budget;
    o.tolerance = 1e-15;  // never met within these budgets
    int calls = 0;
    const ResidualFunction counted = [&](const std::vector<double>& u) {
      ++calls;
      return rosenbrock(u);
    };
    const OptimizeResult lm = levenberg_marquardt(counted, kRosenbrockStart, o);
    EXPECT_EQ(lm.evaluations, calls);
    EXPECT_LE(lm.evaluations, budget);
    EXPECT_FALSE(lm.converged);
    calls = 0;
    const OptimizeResult nm = nelder_mead(counted, kRosenbrockStart, o);
    EXPECT_EQ(nm.evaluations, calls);
    EXPECT_GE(nm.evaluations, budget);
    EXPECT_LE(nm.evaluations, budget + 3);  // finishes its step: at most n + 1 past the budget
    EXPECT_FALSE(nm.converged);
  }
}

TEST(Optimize, SameEvaluationsAndResultEveryTimeAndStartHookAfterTheStart) {
  std::vector<std::vector<double>> seen[2];
  OptimizeResult results[2];
  for (int run = 0; run < 2; ++run) {
    int calls_at_start = -1;
    const ResidualFunction logged = [&](const std::vector<double>& u) {
      seen[run].push_back(u);
      return rosenbrock(u);
    };
    results[run] = levenberg_marquardt(logged, kRosenbrockStart, OptimizeOptions{},
                                       [&] { calls_at_start = int(seen[run].size()); });
    EXPECT_EQ(calls_at_start, 1);
    EXPECT_EQ(seen[run].front(), kRosenbrockStart);
  }
  EXPECT_EQ(seen[0], seen[1]);  // bit for bit
  EXPECT_EQ(results[0].u, results[1].u);
  EXPECT_EQ(results[0].objective, results[1].objective);
  int calls = 0, calls_at_start = -1;
  const ResidualFunction counted = [&](const std::vector<double>& u) {
    ++calls;
    return rosenbrock(u);
  };
  const OptimizeResult a =
      nelder_mead(counted, kRosenbrockStart, {}, [&] { calls_at_start = calls; });
  EXPECT_EQ(calls_at_start, 1);
  const OptimizeResult b = nelder_mead(counted, kRosenbrockStart, {});
  EXPECT_EQ(a.u, b.u);
  EXPECT_EQ(a.evaluations, b.evaluations);
}

TEST(Optimize, InvertsASmallMatrixAndRefusesASingularOne) {
  // [[4, 7], [2, 6]]: determinant 10, inverse [[0.6, -0.7], [-0.2, 0.4]].
  std::vector<std::vector<double>> a = {{4, 7}, {2, 6}};
  ASSERT_TRUE(invert_matrix(a));
  EXPECT_NEAR(a[0][0], 0.6, 1e-15);
  EXPECT_NEAR(a[0][1], -0.7, 1e-15);
  EXPECT_NEAR(a[1][0], -0.2, 1e-15);
  EXPECT_NEAR(a[1][1], 0.4, 1e-15);
  std::vector<std::vector<double>> singular = {{1, 2}, {2, 4}};
  EXPECT_FALSE(invert_matrix(singular));
}

TEST(Optimize, BadOptionsAndStartsNameTheField) {
  OptimizeOptions o;
  o.tolerance = 0;
  EXPECT_NE(error_of([&] { nelder_mead(rosenbrock, kRosenbrockStart, o); }).find("tolerance"),
            std::string::npos);
  o = {};
  o.initial_step = 0.7;
  EXPECT_NE(error_of([&] { o.validate(); }).find("initial_step"), std::string::npos);
  o = {};
  o.jacobian_step = 0;
  EXPECT_NE(error_of([&] { o.validate(); }).find("jacobian_step"), std::string::npos);
  EXPECT_NE(error_of([] {
              levenberg_marquardt(rosenbrock, {0.5, 1.5}, {});
            }).find("u0"),
            std::string::npos);
  EXPECT_NE(error_of([] { levenberg_marquardt(rosenbrock, {}, {}); }).find("u0"),
            std::string::npos);
}

}  // namespace
}  // namespace weft
