#pragma once
// Fitting a model's fiber to the measurement (docs/verify.md "Fit"): at most four physical
// parameters, the same budget for both models, searched in the unit cube of their boxes by
// core/optimize.h on the log residuals of the in-plane curves.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "weft/core/optimize.h"
#include "weft/core/spectrum.h"
#include "weft/verify/measured.h"
#include "weft/verify/metrics.h"
#include "weft/verify/settings.h"

namespace weft {

// One fitted parameter: its box [lo, hi] and start; 'log_scale' searches ln(x) (for scales that
// span decades). The optimizer works in the unit cube u in [0, 1] of each box.
struct FitParameter {
  std::string name, unit;
  double lo = 0, hi = 1, start = 0.5;
  bool log_scale = false;
};

// A parameter's value as its coordinate in the optimizer's unit cube (ln x where log_scale).
double fit_unit(const FitParameter& p, double x);

// The starts of the k-th of several fits of one model (fit_over_seeds): k = 0 the given starts;
// k >= 1 each start moved by a quarter of its box in the search's unit cube, in another pattern of
// directions for each fit (all down, all up, alternating, in pairs), the step halved after every
// eight fits, kept within [0.02, 0.98] of the cube. A search from one start stops at the first
// minimum it meets, and the fit's objective has several (docs/verify.md).
std::vector<FitParameter> fit_start_of(std::vector<FitParameter> params, int k);

// The model being fitted: the in-plane beta [incidence][view] of the measurement's views for a
// parameter vector (in the parameters' own units).
using InplaneModel = std::function<std::vector<std::vector<Rgb>>(const std::vector<double>&)>;

// The search: Levenberg-Marquardt on the log residuals (the objective is a least-squares sum of
// 945 smooth residuals in at most four parameters, so Gauss-Newton steps reach the optimum in a
// few Jacobians), or Nelder-Mead on their RMS (no derivatives; slow from a distant start in four
// dimensions, docs/verify.md "Optimizer").
enum class FitMethod { kLevenbergMarquardt, kNelderMead };
FitMethod parse_fit_method(const std::string& name);  // weft::Error naming "--fit-method"
std::string fit_method_name(FitMethod method);        // "lm" or "nelder-mead"

// The search's options (core/optimize.h; its steps are fractions of each box): max_evaluations
// counts the objective's evaluations during the search (the uncertainty adds 2 p + 1);
// jacobian_step also sets the central differences of the uncertainty at the optimum.
struct FitOptions : OptimizeOptions {
  FitMethod method = FitMethod::kLevenbergMarquardt;
  // The uncertainty at the optimum (add_fit_uncertainty: 2 p + 1 evaluations beyond the search);
  // off for a search whose optimum only seeds another.
  bool uncertainty = true;
  void validate(size_t parameters) const;  // weft::Error naming the option
};

struct FitParameterResult {
  FitParameter parameter;
  double value = 0;
  double sigma = 0;       // one standard deviation (NaN where the Jacobian does not determine it)
  bool at_bound = false;  // within 1e-3 of the box's edge (a constrained optimum)
  // The ray-trace inner model's restarts (fit_inner_model): the standard deviation of the optima
  // of the searches after the first, each on its own proposal, i.e. another realization of the
  // ray trace's noise (NaN with fewer than two). What sigma leaves out: the noise is correlated
  // across the residuals, so it moves the optimum more than independent residuals would.
  double sigma_restarts = std::numeric_limits<double>::quiet_NaN();
  // The fits at several inner seeds (fit_over_seeds, --fit-seeds): the lowest and highest optimum
  // and their standard deviation over the seeds' fits (NaN with fewer than two). Where the
  // measurement does not determine a parameter, the fits at other realizations of the inner
  // model's noise land far apart on a floor of equal objective: this is that spread.
  double seeds_lo = std::numeric_limits<double>::quiet_NaN();
  double seeds_hi = std::numeric_limits<double>::quiet_NaN();
  double sigma_seeds = std::numeric_limits<double>::quiet_NaN();
};

// One of a model's fits at several inner seeds (fit_over_seeds).
struct SeedFit {
  uint64_t seed = 0;
  std::vector<double> values;  // its optimum
  double objective = 0;        // the inner rms_log its search ended at, at its own seed
  // Its optimum's inner rms_log averaged over every seed's inner model (the judge), and their
  // standard deviation (NaN for one seed).
  double objective_over_seeds = 0;
  double objective_over_seeds_sd = std::numeric_limits<double>::quiet_NaN();
  int evaluations = 0;
  bool converged = false;
};

struct FitResult {
  std::string model;        // "computed" or "classic"
  std::string inner_model;  // what the objective evaluated (docs/verify.md)
  std::vector<FitParameterResult> parameters;
  double objective_start = 0, objective = 0;   // rms_log, absolute, of the inner model
  CurveMetrics start_metrics, fitted_metrics;  // the inner model's absolute metrics
  int evaluations = 0;
  bool converged = false;  // the tolerance was met before max_evaluations
  // The ray-trace inner model's searches after the first (fit_inner_model re-centres its proposal
  // on the last optimum and searches again until the optimum settles); 0 for the other inner
  // models. sigma_restarts needs two.
  int restarts = 0;
  std::string method;  // fit_method_name of the search
  double seconds = 0;
  // The fits at each inner seed (fit_over_seeds), the chosen one (this result's) first.
  std::vector<SeedFit> seed_fits;
  std::string uncertainty =
      "Gauss-Newton: covariance s^2 (J^T J)^-1 of the log residuals at the optimum, J by central "
      "differences, s^2 = SSR / (n - p); treats the residuals as independent";
};

// The RMS of fit_residuals: the fit's objective (rms_log, absolute) of a model's curves.
double fit_rms_log(const std::vector<std::vector<Rgb>>& model, const MeasuredInplane& measured);

// max(x, floor) made smooth: x from the floor up, floor^2 / (2 floor - x) below it (continuous in
// value and slope, increasing in x, positive).
double smooth_log_floor(double x, double floor);

// The residuals the fit minimizes: ln(model / measured) at every view, incidence and channel
// where the measurement is positive (the points of rms_log), so the vector's length does not
// depend on the parameters. Both values pass a smooth floor first, at kLogFloorFraction of
// the measurement's own channel maximum (figures.h): an out-of-gamut (negative) component of a
// spectral model's linear sRGB is penalized more the further out it is, with no kink or jump;
// above the floor the residual is ln(model / measured) exactly.
std::vector<double> fit_residuals(const std::vector<std::vector<Rgb>>& model,
                                  const MeasuredInplane& measured);

// Bounded, deterministic minimization of the RMS of fit_residuals (= rms_log, absolute) by
// options.method, then the uncertainty from the Jacobian at the optimum. weft::Error on more than
// four parameters, an empty or reversed box, a start outside it, or bad options.
FitResult fit_inplane(const std::string& model, const std::vector<FitParameter>& parameters,
                      const InplaneModel& inplane, const MeasuredInplane& measured,
                      const FitOptions& options);

// The fit's figures at its optimum (res.parameters' values): the inner model's metrics there and
// each parameter's Gauss-Newton sigma (FitResult::uncertainty); adds its 2 p + 1 evaluations and
// its seconds to res.
void add_fit_uncertainty(FitResult& res, const InplaneModel& inplane,
                         const MeasuredInplane& measured, const FitOptions& options);

// The inner model the fit evaluates (docs/verify.md), both with fixed seeds at every evaluation
// (common random numbers):
//   kRaytrace: the run's own pipeline (spectral fiber bake, then the fiber-level ray trace) with
//   few
//     photons and particles; the bake treats absorption as a weight and the ray trace draws its
//     paths from a proposal table re-centred on the optimum (verify/fit_models.h), so that the
//     objective is smooth in the parameters at the fixed seed;
//   kSummation: the paper's summation table of the same bake; smooth and about 20 times cheaper,
//     but without light travelling between fibers, so its optimum is not the ray trace's.
enum class FitInner { kRaytrace, kSummation };
FitInner parse_fit_inner(const std::string& name);  // weft::Error naming "--fit-inner"
std::string fit_inner_name(FitInner inner);

struct FitInnerSettings {
  FitInner inner = FitInner::kRaytrace;
  int resolution = 6;
  uint64_t fiber_photons_per_band = 5000;
  uint64_t particles_per_bin = 2000;  // kRaytrace: one ray trace
  int summation_samples = 4;          // the summation's
  // The classic fiber table's samples per cell pair: its lobe narrows to roughness 0.05 at the
  // box's bound, which 4 samples resolve so poorly that the fitted objective moved by 0.09 from
  // seed to seed (docs/verify.md, "The fit's time and the inner model's noise").
  int classic_samples = 64;
  uint64_t seed = 1;
  int azimuths = 24;
  int threads = 0;
};
FitInnerSettings fit_inner_settings(const VerifySettings& settings);

}  // namespace weft
