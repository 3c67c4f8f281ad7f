#include "weft/verify/fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common.h"
#include "weft/core/error.h"
#include "weft/verify/figures.h"

namespace weft {

FitInner parse_fit_inner(const std::string& name) {
  if (name == "raytrace") return FitInner::kRaytrace;
  if (name == "summation") return FitInner::kSummation;
  throw Error("", "--fit-inner", "'" + name + "' is not raytrace or summation");
}

std::string fit_inner_name(FitInner inner) {
  return inner == FitInner::kRaytrace ? "raytrace" : "summation";
}

FitInnerSettings fit_inner_settings(const VerifySettings& s) {
  FitInnerSettings f;
  f.seed = s.seed;
  f.azimuths = s.azimuths;
  f.threads = s.threads;
  return f;
}

void FitOptions::validate(size_t parameters) const {
  const int least = 2 * static_cast<int>(parameters) + 2;
  if (max_evaluations < least)
    throw Error("", "--fit-evaluations",
                std::to_string(max_evaluations) + " is fewer than 2 p + 2 = " +
                    std::to_string(least) + " (the simplex and a first step)");
  OptimizeOptions::validate();
}

double smooth_log_floor(double x, double floor) {
  // x itself from the floor up, so the objective is the metrics' rms_log wherever both sides are
  // above it; below, f^2 / (2 f - x): the same value and slope at f, positive and increasing, and
  // its log falls only as ln |x| far out of gamut (a negative value), so a channel pushed through
  // zero by a dye bends the objective without dominating it.
  return x >= floor ? x : floor * floor / (2 * floor - x);
}

std::vector<double> fit_residuals(const std::vector<std::vector<Rgb>>& model,
                                  const MeasuredInplane& measured) {
  if (model.size() != measured.curves.size())
    throw Error(measured.file, "fit", "the model's incidences differ from the measurement's");
  // Each channel's floor, on both sides as in the metrics, from the measurement's maximum, not
  // the model's: it does not move with the parameters, so the objective stays smooth in them.
  double top[3] = {0, 0, 0};
  for (const auto& c : measured.curves)
    for (const auto& b : c.beta)
      for (int k = 0; k < 3; ++k) top[k] = std::max(top[k], b[k]);
  std::vector<double> r;
  for (size_t i = 0; i < model.size(); ++i) {
    const auto& c = measured.curves[i];
    if (model[i].size() != c.view_deg.size())
      throw Error(measured.file, "fit", "the model's views differ from the measurement's");
    for (size_t v = 0; v < c.view_deg.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        const double m = c.beta[v][k], x = model[i][v][k];
        if (!(m > 0)) continue;
        const double f = kLogFloorFraction * top[k];
        r.push_back(std::log(smooth_log_floor(x, f) / smooth_log_floor(m, f)));
      }
  }
  return r;
}

double fit_rms_log(const std::vector<std::vector<Rgb>>& model, const MeasuredInplane& measured) {
  return residual_rms(fit_residuals(model, measured));
}

FitMethod parse_fit_method(const std::string& name) {
  if (name == "lm") return FitMethod::kLevenbergMarquardt;
  if (name == "nelder-mead") return FitMethod::kNelderMead;
  throw Error("", "--fit-method", "'" + name + "' is not lm or nelder-mead");
}

std::string fit_method_name(FitMethod method) {
  return method == FitMethod::kNelderMead ? "nelder-mead" : "lm";
}

double fit_unit(const FitParameter& p, double x) {
  return p.log_scale ? (std::log(x) - std::log(p.lo)) / (std::log(p.hi) - std::log(p.lo))
                     : (x - p.lo) / (p.hi - p.lo);
}

namespace {

double to_value(const FitParameter& p, double u) {
  return p.log_scale ? std::exp(std::log(p.lo) + u * (std::log(p.hi) - std::log(p.lo)))
                     : p.lo + u * (p.hi - p.lo);
}

}  // namespace

std::vector<FitParameter> fit_start_of(std::vector<FitParameter> params, int k) {
  if (k <= 0) return params;
  // Directions per parameter (up to four), one pattern per fit: all down, all up, alternating,
  // then in pairs.
  static constexpr int kSigns[8][4] = {{-1, -1, -1, -1}, {1, 1, 1, 1},   {-1, 1, -1, 1},
                                       {1, -1, 1, -1},   {-1, -1, 1, 1}, {1, 1, -1, -1},
                                       {-1, 1, 1, -1},   {1, -1, -1, 1}};
  const int pattern = (k - 1) % 8;
  const double step = 0.25 / static_cast<double>(1 << std::min((k - 1) / 8, 8));
  for (size_t i = 0; i < params.size(); ++i) {
    FitParameter& p = params[i];
    const double u = fit_unit(p, p.start) + step * kSigns[pattern][i % 4];
    p.start = std::clamp(to_value(p, std::clamp(u, 0.02, 0.98)), p.lo, p.hi);
  }
  return params;
}

namespace {

CurveMetrics absolute_metrics(const std::vector<std::vector<Rgb>>& model,
                              const MeasuredInplane& measured) {
  MetricsAccumulator a;
  for (size_t i = 0; i < model.size(); ++i)
    for (size_t v = 0; v < model[i].size(); ++v)
      for (int k = 0; k < 3; ++k) a.add(model[i][v][k], measured.curves[i].beta[v][k]);
  return a.result();
}

// The fit's objective as core/optimize.h sees it: the residuals at a point of the unit cube of
// the parameters' boxes. Each evaluation is counted in 'evaluations' and its curves are kept in
// 'last' (for the metrics).
ResidualFunction residuals_in_cube(const std::vector<FitParameter>& params,
                                   const InplaneModel& inplane, const MeasuredInplane& measured,
                                   int& evaluations, std::vector<std::vector<Rgb>>& last) {
  return [&params, &inplane, &measured, &evaluations, &last](const std::vector<double>& u) {
    ++evaluations;
    std::vector<double> x(params.size());
    for (size_t k = 0; k < params.size(); ++k)
      x[k] = to_value(params[k], std::clamp(u[k], 0.0, 1.0));
    last = inplane(x);
    return fit_residuals(last, measured);
  };
}

void check_fit_parameters(const std::vector<FitParameter>& params) {
  if (params.empty() || params.size() > 4)
    throw Error("", "--fit-params",
                "fit between one and four parameters (the same budget for both models), not " +
                    std::to_string(params.size()));
  for (const auto& p : params) {
    if (!(p.lo < p.hi) || !std::isfinite(p.lo) || !std::isfinite(p.hi) ||
        (p.log_scale && !(p.lo > 0)))
      throw Error("", p.name, "the fit's box must have lo < hi (and lo > 0 on a log scale)");
    if (!(p.start >= p.lo && p.start <= p.hi))
      throw Error("", p.name,
                  "the start " + fmt(p.start, 6) + " lies outside [" + fmt(p.lo, 6) + ", " +
                      fmt(p.hi, 6) + "]");
  }
}

}  // namespace

FitResult fit_inplane(const std::string& model, const std::vector<FitParameter>& params,
                      const InplaneModel& inplane, const MeasuredInplane& measured,
                      const FitOptions& o) {
  check_fit_parameters(params);
  o.validate(params.size());
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = params.size();
  FitResult res;
  res.model = model;
  std::vector<std::vector<Rgb>> last;  // the latest evaluation's curves (for the metrics)
  const ResidualFunction residuals =
      residuals_in_cube(params, inplane, measured, res.evaluations, last);
  std::vector<double> u0(n);
  for (size_t k = 0; k < n; ++k) u0[k] = fit_unit(params[k], params[k].start);
  const std::function<void()> at_start = [&] {
    res.start_metrics = absolute_metrics(last, measured);
  };
  const OptimizeResult search = o.method == FitMethod::kNelderMead
                                    ? nelder_mead(residuals, u0, o, at_start)
                                    : levenberg_marquardt(residuals, u0, o, at_start);
  res.method = fit_method_name(o.method);
  res.objective_start = search.objective_start;
  res.objective = search.objective;
  res.converged = search.converged;
  for (size_t k = 0; k < n; ++k) {
    FitParameterResult p;
    p.parameter = params[k];
    p.value = to_value(params[k], search.u[k]);
    p.at_bound = search.u[k] < 1e-3 || search.u[k] > 1 - 1e-3;
    p.sigma = std::nan("");
    res.parameters.push_back(p);
  }
  res.seconds = seconds_since(t0);
  if (o.uncertainty) add_fit_uncertainty(res, inplane, measured, o);
  return res;
}

void add_fit_uncertainty(FitResult& res, const InplaneModel& inplane,
                         const MeasuredInplane& measured, const FitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = res.parameters.size();
  std::vector<FitParameter> params;
  std::vector<double> ub(n);
  for (size_t k = 0; k < n; ++k) {
    params.push_back(res.parameters[k].parameter);
    ub[k] = std::clamp(fit_unit(res.parameters[k].parameter, res.parameters[k].value), 0.0, 1.0);
  }
  std::vector<std::vector<Rgb>> last;
  const ResidualFunction residuals =
      residuals_in_cube(params, inplane, measured, res.evaluations, last);
  const std::vector<double> r0 = residuals(ub);
  res.fitted_metrics = absolute_metrics(last, measured);
  const GaussNewtonCovariance cov = gauss_newton_covariance(residuals, ub, r0, o.jacobian_step);
  for (size_t k = 0; k < n; ++k) {
    FitParameterResult& p = res.parameters[k];
    // d value / d u converts the unit-cube standard deviation to the parameter's own units.
    const double dxdu = p.parameter.log_scale
                            ? p.value * (std::log(p.parameter.hi) - std::log(p.parameter.lo))
                            : p.parameter.hi - p.parameter.lo;
    p.sigma = dxdu * cov.sigma(k);
  }
  res.seconds += seconds_since(t0);
}

}  // namespace weft
