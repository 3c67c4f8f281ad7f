// The fit (verify/fit.h) on an analytic model whose log residuals are linear in its parameters,
// ln x (a log-scale box) and y (a linear box), plus a fixed pattern orthogonal to both: the
// least-squares optimum, its residual sum and its Gauss-Newton sigmas follow in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_util.h"
#include "weft/verify/figures.h"
#include "weft/verify/fit.h"

using weft::testing::error_of;

namespace weft {
namespace {

constexpr double kX = 0.35, kY = 0.6;  // the optimum

MeasuredInplane synthetic_measurement() {
  MeasuredInplane m;
  m.file = "synthetic";
  m.curves.push_back({0, {-30, 0, 30}, {Rgb(0.2), Rgb(0.3), Rgb(0.25)}});
  m.curves.push_back({40, {-30, 0, 30}, {Rgb(0.1), Rgb(0.15), Rgb(0.4)}});
  return m;
}

// The pattern: 0.01 (1, -2, 1) over the views times (1, 2, 3) over the channels; it sums to zero
// and is orthogonal to the views' (-1, 0, 1), so it moves neither parameter.
double pattern(size_t view, int channel) {
  return 0.01 * (view == 1 ? -2.0 : 1.0) * (channel + 1);
}

// ln(model / measured) = ln(x / kX) + (y - kY) v / 30 + pattern.
InplaneModel linear_in_log(const MeasuredInplane& m) {
  return [&m](const std::vector<double>& p) {
    std::vector<std::vector<Rgb>> out;
    for (const auto& c : m.curves) {
      auto& curve = out.emplace_back();
      for (size_t v = 0; v < c.view_deg.size(); ++v) {
        Rgb b;
        for (int k = 0; k < 3; ++k)
          b[k] = c.beta[v][k] *
                 std::exp(std::log(p[0] / kX) + (p[1] - kY) * c.view_deg[v] / 30 + pattern(v, k));
        curve.push_back(b);
      }
    }
    return out;
  };
}

const std::vector<FitParameter> kParameters = {{"x", "", 0.05, 1, 0.1, true},
                                               {"y", "", 0, 1, 0.2, false}};

TEST(VerifyFit, LevenbergMarquardtFindsTheOptimumAndItsSigmas) {
  const MeasuredInplane m = synthetic_measurement();
  FitOptions o;
  const FitResult r = fit_inplane("computed", kParameters, linear_in_log(m), m, o);
  EXPECT_EQ(r.method, "lm");
  EXPECT_TRUE(r.converged);
  ASSERT_EQ(r.parameters.size(), 2u);
  // The search stops once no step longer than 1e-3 of a box is left (core/optimize.h): within
  // about that of the optimum, 1e-3 of ln 20 in ln x and 1e-3 in y.
  EXPECT_NEAR(std::log(r.parameters[0].value / kX), 0.0, 3e-3);
  EXPECT_NEAR(r.parameters[1].value, kY, 1e-3);
  EXPECT_FALSE(r.parameters[0].at_bound);
  // 18 residuals (2 incidences, 3 views, 3 channels); at the optimum they are the pattern:
  // SSR = 2 (1 + 4 + 1)(1 + 4 + 9) 1e-4, s^2 = SSR / (18 - 2). The design's columns, 1 and v / 30,
  // are orthogonal (18 and 12 as their squared norms), so Var ln x = s^2 / 18, Var y = s^2 / 12,
  // and sigma x = x sigma ln x. Near the optimum the sum of squares is off by second order.
  const double ssr = 2 * 6 * 14 * 1e-4, s2 = ssr / 16;
  EXPECT_GE(r.objective, std::sqrt(ssr / 18) - 1e-12);
  EXPECT_NEAR(r.objective, std::sqrt(ssr / 18), 1e-5);
  EXPECT_NEAR(r.fitted_metrics.rms_log, r.objective, 1e-12);  // the same point
  EXPECT_NEAR(r.parameters[0].sigma / (kX * std::sqrt(s2 / 18)), 1.0, 1e-3);
  EXPECT_NEAR(r.parameters[1].sigma / std::sqrt(s2 / 12), 1.0, 1e-3);
  // The start's figures: ln(0.1 / 0.35) and (0.2 - 0.6) v / 30 added to the pattern.
  EXPECT_GT(r.objective_start, 1.0);
  EXPECT_NEAR(r.start_metrics.rms_log, r.objective_start, 1e-12);
  // The uncertainty's 2 p + 1 evaluations come after the search's.
  EXPECT_LE(r.evaluations, o.max_evaluations + 5);
}

TEST(VerifyFit, NelderMeadFindsTheOptimum) {
  const MeasuredInplane m = synthetic_measurement();
  FitOptions o;
  o.method = FitMethod::kNelderMead;
  o.max_evaluations = 400;
  const FitResult r = fit_inplane("classic", kParameters, linear_in_log(m), m, o);
  EXPECT_EQ(r.method, "nelder-mead");
  EXPECT_TRUE(r.converged);
  // Converged: edges below 1e-3 of each box (ln x spans ln 20 = 3.0).
  EXPECT_NEAR(std::log(r.parameters[0].value / kX), 0.0, 5e-3);
  EXPECT_NEAR(r.parameters[1].value, kY, 2e-3);
}

TEST(VerifyFit, ResidualsAreTheLogRatiosWhereTheMeasurementIsPositive) {
  MeasuredInplane m;
  m.file = "m.csv";
  m.curves.push_back({0, {0, 30}, {Rgb(0.5, 0.0, 0.5), Rgb(0.4)}});
  const std::vector<std::vector<Rgb>> model = {{Rgb(1.0, 1.0, 0.0), Rgb(0.4)}};
  const std::vector<double> r = fit_residuals(model, m);
  ASSERT_EQ(r.size(), 5u);  // the measured zero is left out
  // Above the floor (1e-3 of the channel's measured maximum) the residual is ln(x / m) exactly.
  EXPECT_DOUBLE_EQ(r[0], std::log(2.0));
  // A model zero sits at half the floor.
  EXPECT_DOUBLE_EQ(r[1], std::log(kLogFloorFraction * 0.5 / 2 / 0.5));
  EXPECT_DOUBLE_EQ(r[2], 0.0);
  EXPECT_NE(error_of([&] { fit_residuals({}, m); }).find("incidences"), std::string::npos);
}

// The floor is smooth and increasing: a negative (out-of-gamut) model value costs more than a
// zero, the further out the more, with no jump at zero (the fit's objective stays smooth in a dye
// that drives a channel through zero).
TEST(VerifyFit, ResidualFloorIsSmoothAndIncreasingThroughZero) {
  const double f = 1e-3;
  EXPECT_EQ(smooth_log_floor(f, f), f);
  EXPECT_EQ(smooth_log_floor(0.3, f), 0.3);
  EXPECT_DOUBLE_EQ(smooth_log_floor(0, f), f / 2);
  EXPECT_DOUBLE_EQ(smooth_log_floor(-98 * f, f), f / 100);  // out of gamut: f^2 / (2 f + |x|)
  // Continuous in value and slope at the floor.
  const double h = 1e-9;
  EXPECT_NEAR((smooth_log_floor(f, f) - smooth_log_floor(f - h, f)) / h, 1.0, 1e-5);
  double last = 0;
  for (int k = -100; k <= 100; ++k) {
    const double x = k * 1e-4, y = smooth_log_floor(x, f);
    EXPECT_GT(y, last) << x;
    // The step in ln y between neighbours is at most the step over the floor (0.1): no jump.
    if (k > -100) EXPECT_LE(std::log(y / last), 0.1 + 1e-12) << x;
    last = y;
  }
}

TEST(VerifyFit, OptionsNameTheirField) {
  FitOptions o;
  o.max_evaluations = 5;
  EXPECT_NE(error_of([&] { o.validate(2); }).find("--fit-evaluations"), std::string::npos);
  o = {};
  o.jacobian_step = 0.5;
  EXPECT_NE(error_of([&] { o.validate(2); }).find("jacobian_step"), std::string::npos);
  EXPECT_EQ(parse_fit_method("nelder-mead"), FitMethod::kNelderMead);
  EXPECT_NE(error_of([] { parse_fit_method("bfgs"); }).find("--fit-method"), std::string::npos);
}

}  // namespace
}  // namespace weft

// The starts of a model's several fits: the given ones first, then each moved a quarter of its box
// in the unit cube in another pattern (all down, all up, alternating), kept inside [0.02, 0.98];
// after eight patterns the step halves.
TEST(Fit, SeveralFitsStartAQuarterOfTheBoxApartInOtherPatterns) {
  const std::vector<weft::FitParameter> given = {{"scale", "", 0.1, 10, 1, true},
                                                 {"alpha", "", 0.05, 1, 0.35, false},
                                                 {"low", "", 0, 1, 0.1, false}};
  auto unit = [&](const std::vector<weft::FitParameter>& ps, size_t i) {
    return weft::fit_unit(ps[i], ps[i].start);
  };
  const auto same = weft::fit_start_of(given, 0);
  for (size_t i = 0; i < given.size(); ++i) EXPECT_EQ(same[i].start, given[i].start);
  const auto down = weft::fit_start_of(given, 1), up = weft::fit_start_of(given, 2),
             alternating = weft::fit_start_of(given, 3), finer = weft::fit_start_of(given, 9);
  EXPECT_NEAR(down[0].start, std::pow(10.0, -0.5), 1e-12);  // ln-box [0.1, 10]: a quarter is 10^0.5
  EXPECT_NEAR(unit(down, 1), unit(given, 1) - 0.25, 1e-12);
  EXPECT_NEAR(unit(down, 2), 0.02, 1e-12);  // 0.1 - 0.25 is outside: kept at 0.02
  EXPECT_NEAR(unit(up, 0), 0.75, 1e-12);
  EXPECT_NEAR(unit(up, 2), 0.35, 1e-12);
  EXPECT_NEAR(unit(alternating, 0), 0.25, 1e-12);
  EXPECT_NEAR(unit(alternating, 1), unit(given, 1) + 0.25, 1e-12);
  EXPECT_NEAR(unit(finer, 0), 0.375, 1e-12);  // the first pattern again, at half the step
  for (const auto& ps : {down, up, alternating, finer})
    for (size_t i = 0; i < ps.size(); ++i) {
      EXPECT_GE(ps[i].start, ps[i].lo);
      EXPECT_LE(ps[i].start, ps[i].hi);
    }
}
