#pragma once
// weft verify --fit (docs/verify.md): the physical parameters of a fiber spec that the fit may
// vary, and the inner models the fit evaluates, for the command and its tests (header-only: the
// integrators library that runs the fit does not link the fiber physics).
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/verify/verify.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft {

// The spec's parameters a fit may vary, by name. Scales multiply the spec's own values, so 1 is
// the spec as given.
inline const std::vector<std::string>& spec_fit_parameter_names() {
  static const std::vector<std::string> names = {"dye_scale", "particle_fraction_scale",
                                                 "particle_radius_scale", "roughness_alpha"};
  return names;
}

// Parses --fit-params ("a,b,..."): known names, no repeats, at most four.
inline std::vector<std::string> parse_spec_fit_names(const std::string& list) {
  std::vector<std::string> out;
  std::string cur;
  const auto& known = spec_fit_parameter_names();
  auto flush = [&] {
    if (cur.empty()) throw Error("", "--fit-params", "an empty name in '" + list + "'");
    if (std::find(known.begin(), known.end(), cur) == known.end())
      throw Error("", "--fit-params",
                  "'" + cur +
                      "' is not one of dye_scale, particle_fraction_scale, "
                      "particle_radius_scale, roughness_alpha");
    if (std::find(out.begin(), out.end(), cur) != out.end())
      throw Error("", "--fit-params", "'" + cur + "' is named twice");
    out.push_back(cur);
    cur.clear();
  };
  for (char c : list) {
    if (c == ',')
      flush();
    else
      cur.push_back(c);
  }
  flush();
  if (out.size() > 4) throw Error("", "--fit-params", "at most four parameters (the budget of both models)");
  return out;
}

// The boxes: scales over a decade or more each way, on a log scale; the particles' total volume
// fraction stays at or below 0.5 (the spec allows 0.74 per species).
inline std::vector<FitParameter> spec_fit_parameters(const FiberSpec& spec,
                                                     const std::vector<std::string>& names) {
  std::vector<FitParameter> out;
  for (const auto& n : names) {
    if (n == "dye_scale") {
      out.push_back({n, "x spec's absorption", 0.1, 10, 1, true});
    } else if (n == "particle_fraction_scale" || n == "particle_radius_scale") {
      if (spec.species.empty())
        throw Error(spec.name, "--fit-params", "'" + n + "': the spec has no particle species");
      if (n == "particle_radius_scale") {
        out.push_back({n, "x spec's radii", 0.25, 4, 1, true});
      } else {
        double total = 0;
        for (const auto& s : spec.species) total += s.volume_fraction;
        if (!(total > 0))
          throw Error(spec.name, "--fit-params", "'" + n + "': the particles' volume is zero");
        out.push_back({n, "x spec's volume fractions", 0.1, std::min(10.0, 0.5 / total), 1, true});
      }
    } else {
      out.push_back({n, "", std::min(0.05, spec.roughness_alpha), 1, spec.roughness_alpha, false});
    }
  }
  return out;
}

inline FiberSpec apply_spec_fit(FiberSpec spec, const std::vector<std::string>& names,
                                const std::vector<double>& values) {
  for (size_t k = 0; k < names.size(); ++k) {
    const double v = values[k];
    if (names[k] == "dye_scale")
      for (double& a : spec.host_absorption_per_um) a *= v;
    else if (names[k] == "particle_fraction_scale")
      for (auto& s : spec.species) s.volume_fraction *= v;
    else if (names[k] == "particle_radius_scale")
      for (auto& s : spec.species) s.size.radius_um *= v;
    else
      spec.roughness_alpha = v;
  }
  return spec;
}

// What verify's fiber bakes and paper's summations are, from its settings: one place for the run's
// bake (through the bake cache, and again for the fitted spec) and the fit's inner models. The
// run's bake is spectral (the colour table needs the spectrum) with the default weights; the fit's
// inner bake ('fit_inner') is RGB with absorption as a weight, so that at its fixed seed the table
// is a smooth function of dye_scale (transport.h, docs/verify.md).
inline FiberTableBakeOptions verify_bake_options(int resolution, uint64_t photons_per_band,
                                                 uint64_t seed, int threads, bool fit_inner) {
  FiberTableBakeOptions b;
  b.resolution = resolution;
  b.photons_per_band = photons_per_band;
  b.seed = seed;
  b.threads = threads;
  b.spectral = !fit_inner;
  if (fit_inner) b.weight_mode = WeightMode::absorption_weight;
  return b;
}

inline FabricSummationOptions verify_summation_options(int resolution, int samples_per_cell,
                                                       uint64_t seed, int threads) {
  FabricSummationOptions so;
  so.method = FabricSummation::kPaper;
  so.resolution = resolution;
  so.samples_per_cell = samples_per_cell;
  so.seed = seed;
  so.threads = threads;
  return so;
}

inline std::string inner_step_name(const FitInnerSettings& f) {
  return f.inner == FitInner::kRaytrace
             ? "fiber-level ray trace (R = " + std::to_string(f.resolution) + ", " +
                   std::to_string(f.particles_per_bin) + " particles per incident bin)"
             : "paper's summation table (R = " + std::to_string(f.resolution) + ", " +
                   std::to_string(f.summation_samples) + " samples per cell pair)";
}

inline std::string computed_inner_model_name(const FitInnerSettings& f) {
  return inner_step_name(f) + " of an RGB fiber bake (" + std::to_string(f.fiber_photons_per_band) +
         " photons per band), seed " + std::to_string(f.seed) + " at every evaluation";
}

inline std::string classic_inner_model_name(const FitInnerSettings& f) {
  return inner_step_name(f) + " of the classic fiber table (" +
         std::to_string(f.summation_samples) + " samples per cell pair), seed " +
         std::to_string(f.seed) + " at every evaluation";
}

// The inner model's step from a fiber table to the curves, with the fixed seed. The ray trace
// draws its paths from 'proposal' when given (FabricRaytraceOptions::proposal): the fit passes the
// table of its start, so that the objective is smooth in the parameters (docs/verify.md).
inline std::vector<std::vector<Rgb>> inner_fabric_curves(
    const WovenSample& sample, const TabulatedBsdfTable& fiber, const FitInnerSettings& f,
    const MeasuredInplane& measured, const TabulatedBsdfTable* proposal = nullptr) {
  if (f.inner == FitInner::kSummation)
    return table_curves(
        sum_fabric_table(
            fiber, verify_summation_options(f.resolution, f.summation_samples, f.seed, f.threads)),
        measured, f.azimuths);
  FabricRaytraceOptions o;
  o.resolution = f.resolution;
  o.particles_per_bin = f.particles_per_bin;
  o.seed = f.seed;
  o.threads = f.threads;
  o.proposal = proposal;
  return table_curves(raytrace_fabric_table(sample, fiber, o).table, measured, f.azimuths);
}

// The computed model's inner fiber table: an RGB bake with absorption as a weight, fixed seed.
inline TabulatedBsdfTable computed_inner_fiber_table(const FiberSpec& spec,
                                                     const FitInnerSettings& f) {
  const FiberTableBakeOptions b =
      verify_bake_options(f.resolution, f.fiber_photons_per_band, f.seed, f.threads, true);
  return bake_fiber_table(spec, b).table;
}

// The computed model's inner curves: its inner fiber table, then the inner model's step.
inline std::vector<std::vector<Rgb>> computed_inner_curves(
    const FiberSpec& spec, const WovenSample& sample, const FitInnerSettings& f,
    const MeasuredInplane& measured, const TabulatedBsdfTable* proposal = nullptr) {
  return inner_fabric_curves(sample, computed_inner_fiber_table(spec, f), f, measured, proposal);
}

// The classic model's inner fiber table (fixed seed).
inline TabulatedBsdfTable classic_inner_fiber_table(const Rgb& diffuse,
                                                    const MicrofacetDistribution& d, double ior,
                                                    const FitInnerSettings& f) {
  return classic_fiber_table(diffuse, d, ior, f.resolution, f.summation_samples, f.seed, f.threads);
}

// The classic model's inner curves: its fiber table, then the same step.
inline std::vector<std::vector<Rgb>> classic_inner_curves(
    const Rgb& diffuse, const MicrofacetDistribution& d, double ior, const WovenSample& sample,
    const FitInnerSettings& f, const MeasuredInplane& measured,
    const TabulatedBsdfTable* proposal = nullptr) {
  return inner_fabric_curves(sample, classic_inner_fiber_table(diffuse, d, ior, f), f, measured,
                             proposal);
}

// The fit of one model on its inner model. 'table_of' makes the model's inner fiber table for a
// parameter vector. With the ray-trace inner model the particles draw their paths from a proposal
// table (FabricRaytraceOptions::proposal), so that at the fixed seed the objective is smooth in
// the parameters: first the start's table; the reweighted estimate's noise grows with the distance
// from the proposal, so the proposal is then re-centred on the optimum and the search restarted
// there, until a search converges without moving more than 1 % of any box (in the search's unit
// cube) from its proposal's point, or the evaluations are spent (options.max_evaluations over
// all stages; the uncertainty, computed once at the last stage's optimum with its proposal, adds
// 2 p + 1). The result: the last stage's optimum and uncertainty, the first's start, the
// evaluations and seconds of all.
inline FitResult fit_inner_model(
    const std::string& model, std::vector<FitParameter> parameters,
    const std::function<TabulatedBsdfTable(const std::vector<double>&)>& table_of,
    const WovenSample& sample, const FitInnerSettings& f, const MeasuredInplane& measured,
    const FitOptions& options) {
  const auto curves_of = [&](const TabulatedBsdfTable* proposal) -> InplaneModel {
    return [&, proposal](const std::vector<double>& x) {
      return inner_fabric_curves(sample, table_of(x), f, measured, proposal);
    };
  };
  if (f.inner != FitInner::kRaytrace)
    return fit_inplane(model, parameters, curves_of(nullptr), measured, options);
  const std::vector<FitParameter> given = parameters;
  FitResult first, last;
  int evaluations = 0;
  double seconds = 0, moved = 0, previous_move = 0;
  std::vector<std::vector<double>> restart_optima;  // of the searches after the first
  TabulatedBsdfTable proposal;
  for (int stage = 0;; ++stage) {
    std::vector<double> x;
    for (const auto& p : parameters) x.push_back(p.start);
    proposal = table_of(x);
    FitOptions o = options;
    o.max_evaluations = options.max_evaluations - evaluations;
    o.uncertainty = false;  // the last stage's, once it is known to be the last (below)
    // A restart refines where the last search ended: its simplex spans twice the last move (the
    // re-centred proposal moves the optimum by about the estimate's noise), at least 0.02 of the
    // box, not the first search's whole step.
    // (Nelder-Mead's; Levenberg-Marquardt takes its steps from the Jacobian.)
    if (stage > 0) o.initial_step = std::clamp(2 * moved, 0.02, options.initial_step);
    last = fit_inplane(model, parameters, curves_of(&proposal), measured, o);
    evaluations += last.evaluations;
    seconds += last.seconds;
    if (stage == 0) first = last;
    if (stage > 0) {
      restart_optima.emplace_back();
      for (const auto& p : last.parameters) restart_optima.back().push_back(p.value);
    }
    previous_move = moved;
    moved = 0;
    for (size_t k = 0; k < parameters.size(); ++k)
      moved = std::max(moved, std::abs(fit_unit(parameters[k], last.parameters[k].value) -
                                       fit_unit(parameters[k], x[k])));
    // Settled: the search stayed within 1 % of its proposal's point, or (from the second restart
    // on) moved no more than the restart before it: the moves no longer shrink, so what is left is
    // the estimate's own noise (each proposal is another realization of the ray trace), which
    // further restarts would only chase.
    const bool settled = last.converged && (moved < 0.01 || (stage >= 2 && moved <= previous_move));
    // A restart needs the simplex and a first step (FitOptions::validate).
    const int least = 2 * static_cast<int>(parameters.size()) + 2;
    if (settled || options.max_evaluations - evaluations < least) {
      last.converged = settled;
      break;
    }
    for (size_t k = 0; k < parameters.size(); ++k) parameters[k].start = last.parameters[k].value;
  }
  for (size_t k = 0; k < given.size(); ++k) {
    last.parameters[k].parameter = given[k];
    const size_t n = restart_optima.size();
    if (n < 2) continue;
    double mean = 0, ss = 0;
    for (const auto& o : restart_optima) mean += o[k] / static_cast<double>(n);
    for (const auto& o : restart_optima) ss += (o[k] - mean) * (o[k] - mean);
    last.parameters[k].sigma_restarts = std::sqrt(ss / static_cast<double>(n - 1));
  }
  last.objective_start = first.objective_start;
  last.start_metrics = first.start_metrics;
  last.evaluations = evaluations;
  last.seconds = seconds;
  if (options.uncertainty) add_fit_uncertainty(last, curves_of(&proposal), measured, options);
  return last;
}

// The classic model's four: its diffuse colour per channel (a reflectance, on a log scale: the
// measured fabric's green and blue are an order below its red) and its roughness. A start below
// the box's floor of 0.005 starts at the floor.
inline std::vector<FitParameter> classic_fit_parameters(const Rgb& diffuse, double alpha) {
  auto start = [](double v) { return std::clamp(v, 0.005, 1.0); };
  return {{"diffuse_r", "reflectance", 0.005, 1, start(diffuse.r), true},
          {"diffuse_g", "reflectance", 0.005, 1, start(diffuse.g), true},
          {"diffuse_b", "reflectance", 0.005, 1, start(diffuse.b), true},
          {"roughness_alpha", "", 0.05, 1, std::clamp(alpha, 0.05, 1.0), false}};
}

}  // namespace weft
