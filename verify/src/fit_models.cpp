// weft verify --fit: the spec's fit parameters (one table of named setters), the inner models and
// the fit of one model with its proposal re-centred between restarts (fit_models.h).
#include "weft/verify/fit_models.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "common.h"
#include "weft/core/error.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/recorded_paths.h"
#include "weft/materials/classic_fiber.h"
#include "weft/verify/figures.h"

namespace weft {

namespace {

// The particle parameters need particles to scale.
void require_species(const FiberSpec& spec, const std::string& name) {
  if (spec.species.empty())
    throw Error(spec.name, "--fit-params", "'" + name + "': the spec has no particle species");
}

// The recipe's component 'index', with a concentration to scale.
const DyeComponent& require_dye(const FiberSpec& spec, size_t index, const std::string& name) {
  if (index >= spec.dyes.size())
    throw Error(
        spec.name, "--fit-params",
        "'" + name + "': the spec's dye recipe has " + std::to_string(spec.dyes.size()) + " dyes");
  const DyeComponent& c = spec.dyes[index];
  if (!(c.concentration_owf_percent > 0))
    throw Error(spec.name, "--fit-params",
                "'" + name + "': dye '" + c.dye + "' has no concentration to scale");
  return c;
}

// dyeK_concentration, K = 0 .. kMaxDyeComponents - 1: the recipe's K-th concentration itself
// (% owf), over a decade each way within the spec's bounds. Named on request only (not among the
// default parameters: a spec without a recipe has none).
const std::vector<SpecFitRule>& dye_concentration_rules() {
  using Box = SpecFitRule::Box;
  static const std::vector<SpecFitRule> rules = [] {
    std::vector<SpecFitRule> r;
    for (size_t k = 0; k < static_cast<size_t>(kMaxDyeComponents); ++k)
      r.push_back(
          {"dye" + std::to_string(k) + "_concentration", "% owf",
           [k](const FiberSpec& spec, const std::string& name) {
             const double c = require_dye(spec, k, name).concentration_owf_percent;
             return Box{c / 10, std::min(10 * c, kMaxDyeOwfPercent), c, true};
           },
           [k](FiberSpec& spec, double v) { spec.dyes.at(k).concentration_owf_percent = v; }});
    return r;
  }();
  return rules;
}

}  // namespace

const std::vector<SpecFitRule>& spec_fit_rules() {
  using Box = SpecFitRule::Box;
  static const std::vector<SpecFitRule> rules = {
      {"dye_scale", "x spec's absorption",
       [](const FiberSpec&, const std::string&) {
         return Box{0.1, 10, 1, true};
       },
       // The absorption as given and the recipe's concentrations alike.
       [](FiberSpec& spec, double v) {
         for (double& a : spec.host_absorption_per_um) a *= v;
         for (auto& c : spec.dyes) c.concentration_owf_percent *= v;
       }},
      {"particle_fraction_scale", "x spec's volume fractions",
       [](const FiberSpec& spec, const std::string& name) {
         require_species(spec, name);
         double total = 0;
         for (const auto& s : spec.species) total += s.volume_fraction;
         if (!(total > 0))
           throw Error(spec.name, "--fit-params", "'" + name + "': the particles' volume is zero");
         return Box{0.1, std::min(10.0, 0.5 / total), 1, true};
       },
       [](FiberSpec& spec, double v) {
         for (auto& s : spec.species) s.volume_fraction *= v;
       }},
      {"particle_radius_scale", "x spec's radii",
       [](const FiberSpec& spec, const std::string& name) {
         require_species(spec, name);
         return Box{0.25, 4, 1, true};
       },
       [](FiberSpec& spec, double v) {
         for (auto& s : spec.species) s.size.radius_um *= v;
       }},
      // The roughness itself, on a linear scale; a spec smoother than 0.05 keeps its own floor.
      {"roughness_alpha", "",
       [](const FiberSpec& spec, const std::string&) {
         return Box{std::min(0.05, spec.roughness_alpha), 1, spec.roughness_alpha, false};
       },
       [](FiberSpec& spec, double v) { spec.roughness_alpha = v; }},
  };
  return rules;
}

const SpecFitRule& spec_fit_rule(const std::string& name) {
  for (const auto& r : spec_fit_rules())
    if (r.name == name) return r;
  for (const auto& r : dye_concentration_rules())
    if (r.name == name) return r;
  throw Error("", "--fit-params",
              "'" + name + "' is not one of " + spec_fit_parameter_list(", ") +
                  " or dyeK_concentration (K = 0.." + std::to_string(kMaxDyeComponents - 1) +
                  ", the recipe's K-th dye)");
}

const std::vector<std::string>& spec_fit_parameter_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& r : spec_fit_rules()) out.push_back(r.name);
    return out;
  }();
  return names;
}

std::string spec_fit_parameter_list(const std::string& separator) {
  std::string s;
  for (const auto& n : spec_fit_parameter_names()) s += (s.empty() ? "" : separator) + n;
  return s;
}

std::vector<std::string> parse_spec_fit_names(const std::string& list) {
  std::vector<std::string> out;
  std::string cur;
  auto flush = [&] {
    if (cur.empty()) throw Error("", "--fit-params", "an empty name in '" + list + "'");
    (void)spec_fit_rule(cur);
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
  if (out.size() > 4)
    throw Error("", "--fit-params", "at most four parameters (the budget of both models)");
  return out;
}

std::vector<FitParameter> spec_fit_parameters(const FiberSpec& spec,
                                              const std::vector<std::string>& names) {
  std::vector<FitParameter> out;
  for (const auto& n : names) {
    const SpecFitRule& rule = spec_fit_rule(n);
    const SpecFitRule::Box b = rule.box(spec, rule.name);
    out.push_back({rule.name, rule.unit, b.lo, b.hi, b.start, b.log_scale});
  }
  return out;
}

FiberSpec apply_spec_fit(FiberSpec spec, const std::vector<std::string>& names,
                         const std::vector<double>& values) {
  for (size_t k = 0; k < names.size(); ++k) spec_fit_rule(names[k]).apply(spec, values[k]);
  return spec;
}

std::vector<FitParameter> classic_fit_parameters(const Rgb& diffuse, double alpha) {
  auto start = [](double v) { return std::clamp(v, 0.005, 1.0); };
  return {{"diffuse_r", "reflectance", 0.005, 1, start(diffuse.r), true},
          {"diffuse_g", "reflectance", 0.005, 1, start(diffuse.g), true},
          {"diffuse_b", "reflectance", 0.005, 1, start(diffuse.b), true},
          {"roughness_alpha", "", 0.05, 1, std::clamp(alpha, 0.05, 1.0), false}};
}

FiberTableBakeOptions verify_bake_options(const FiberSpec& spec, int resolution,
                                          uint64_t photons_per_band, uint64_t seed, int threads,
                                          bool fit_inner) {
  FiberTableBakeOptions b = fiber_bake_defaults(spec);
  b.resolution = resolution;
  b.photons_per_band = photons_per_band;
  b.seed = seed;
  b.threads = threads;
  // Spectral in the fit too: an RGB bake of a saturated dye has no valid table (its linear-sRGB
  // components leave [0, albedo]), and clipping them puts a kink in the objective.
  b.spectral = true;
  if (fit_inner) {
    // The fit's inner bake keeps plain exits, one surface sample and random entries: next-event
    // inner bakes made the fits spread more (docs/verify.md), and its photons per band are the
    // fit's own (FitInnerSettings).
    b.weight_mode = WeightMode::absorption_weight;
    b.estimator = FiberExitEstimator::kPlain;
    b.surface_samples = 1;
    b.entry = FiberEntrySampling::kRandom;
  }
  return b;
}

FabricSummationOptions verify_summation_options(int resolution, int samples_per_cell, uint64_t seed,
                                                int threads) {
  FabricSummationOptions so;
  so.method = FabricSummation::kPaper;
  so.resolution = resolution;
  so.samples_per_cell = samples_per_cell;
  so.seed = seed;
  so.threads = threads;
  return so;
}

namespace {

std::string inner_step_name(const FitInnerSettings& f) {
  return f.inner == FitInner::kRaytrace
             ? "fiber-level ray trace (R = " + std::to_string(f.resolution) + ", " +
                   std::to_string(f.particles_per_bin) + " particles per incident bin)"
             : "paper's summation table (R = " + std::to_string(f.resolution) + ", " +
                   std::to_string(f.summation_samples) + " samples per cell pair)";
}

}  // namespace

std::string computed_inner_model_name(const FitInnerSettings& f) {
  return inner_step_name(f) + " of a spectral fiber bake (" +
         std::to_string(f.fiber_photons_per_band) + " photons per band), seed " +
         std::to_string(f.seed) + " at every evaluation";
}

std::string classic_inner_model_name(const FitInnerSettings& f) {
  return inner_step_name(f) + " of the classic fiber table (" + std::to_string(f.classic_samples) +
         " samples per cell pair), seed " + std::to_string(f.seed) + " at every evaluation";
}

FabricRaytraceOptions inner_raytrace_options(const FitInnerSettings& f,
                                             const TabulatedBsdfTable* proposal) {
  FabricRaytraceOptions o;
  o.resolution = f.resolution;
  o.particles_per_bin = f.particles_per_bin;
  o.seed = f.seed;
  o.threads = f.threads;
  o.proposal = proposal;
  return o;
}

std::vector<std::vector<Rgb>> inner_fabric_curves(const WovenSample& sample,
                                                  const TabulatedBsdfTable& fiber,
                                                  const FitInnerSettings& f,
                                                  const MeasuredInplane& measured,
                                                  const TabulatedBsdfTable* proposal) {
  if (f.inner == FitInner::kSummation)
    return table_curves(
        sum_fabric_table(
            fiber, verify_summation_options(f.resolution, f.summation_samples, f.seed, f.threads)),
        measured, f.azimuths);
  return table_curves(
      raytrace_fabric_table(sample, fiber, inner_raytrace_options(f, proposal)).table, measured,
      f.azimuths);
}

TabulatedBsdfTable computed_inner_fiber_table(const FiberSpec& spec, const FitInnerSettings& f) {
  const FiberTableBakeOptions b =
      verify_bake_options(spec, f.resolution, f.fiber_photons_per_band, f.seed, f.threads, true);
  return bake_fiber_table(spec, b).table;
}

std::vector<std::vector<Rgb>> computed_inner_curves(const FiberSpec& spec,
                                                    const WovenSample& sample,
                                                    const FitInnerSettings& f,
                                                    const MeasuredInplane& measured,
                                                    const TabulatedBsdfTable* proposal) {
  return inner_fabric_curves(sample, computed_inner_fiber_table(spec, f), f, measured, proposal);
}

TabulatedBsdfTable classic_inner_fiber_table(const Rgb& diffuse, const MicrofacetDistribution& d,
                                             double ior, const FitInnerSettings& f) {
  return classic_fiber_table(diffuse, d, ior, f.resolution, f.classic_samples, f.seed, f.threads);
}

std::vector<std::vector<Rgb>> classic_inner_curves(const Rgb& diffuse,
                                                   const MicrofacetDistribution& d, double ior,
                                                   const WovenSample& sample,
                                                   const FitInnerSettings& f,
                                                   const MeasuredInplane& measured,
                                                   const TabulatedBsdfTable* proposal) {
  return inner_fabric_curves(sample, classic_inner_fiber_table(diffuse, d, ior, f), f, measured,
                             proposal);
}

namespace {

// The largest move of a search from its proposal's point, in the search's unit cube.
double largest_move(const std::vector<FitParameter>& parameters, const std::vector<double>& from,
                    const FitResult& search) {
  double moved = 0;
  for (size_t k = 0; k < parameters.size(); ++k)
    moved = std::max(moved, std::abs(fit_unit(parameters[k], search.parameters[k].value) -
                                     fit_unit(parameters[k], from[k])));
  return moved;
}

// Each parameter's standard deviation over the restarts' optima (sigma_restarts; NaN, as
// FitParameterResult starts, with fewer than two), and the given parameters in place of the last
// stage's boxes (whose starts are a restart's).
void set_restart_spread(FitResult& last, const std::vector<FitParameter>& given,
                        const std::vector<std::vector<double>>& restart_optima) {
  for (size_t k = 0; k < given.size(); ++k) {
    last.parameters[k].parameter = given[k];
    if (restart_optima.size() < 2) continue;
    std::vector<double> v;
    for (const auto& o : restart_optima) v.push_back(o[k]);
    last.parameters[k].sigma_restarts = sample_sd(v);
  }
}

}  // namespace

FitResult fit_inner_model(
    const std::string& model, std::vector<FitParameter> parameters,
    const std::function<TabulatedBsdfTable(const std::vector<double>&)>& table_of,
    const WovenSample& sample, const FitInnerSettings& f, const MeasuredInplane& measured,
    const FitOptions& options) {
  if (f.inner != FitInner::kRaytrace)
    return fit_inplane(
        model, parameters,
        [&](const std::vector<double>& x) {
          return inner_fabric_curves(sample, table_of(x), f, measured);
        },
        measured, options);
  // The ray trace under the proposal, its paths traced once per proposal and re-weighted for each
  // evaluation's table: the bits of tracing that table with the proposal (recorded_paths.h).
  RecordedFabricPaths paths;
  const InplaneModel reweighted = [&](const std::vector<double>& x) {
    return table_curves(reweight_fabric_paths(paths, table_of(x), f.threads).table, measured,
                        f.azimuths);
  };
  const std::vector<FitParameter> given = parameters;
  FitResult first, last;
  int evaluations = 0;
  double seconds = 0, moved = 0, previous_move = 0;
  std::vector<std::vector<double>> restart_optima;  // of the searches after the first
  for (int stage = 0;; ++stage) {
    std::vector<double> x;
    for (const auto& p : parameters) x.push_back(p.start);
    const auto t0 = std::chrono::steady_clock::now();
    paths = record_fabric_paths(sample, table_of(x), inner_raytrace_options(f, nullptr));
    FitOptions o = options;
    o.max_evaluations = options.max_evaluations - evaluations;
    o.uncertainty = false;  // the last stage's, once it is known to be the last (below)
    // A restart refines where the last search ended: its simplex spans twice the last move (the
    // re-centred proposal moves the optimum by about the estimate's noise), at least 0.02 of the
    // box, not the first search's whole step.
    // (Nelder-Mead's; Levenberg-Marquardt takes its steps from the Jacobian.)
    if (stage > 0) o.initial_step = std::clamp(2 * moved, 0.02, options.initial_step);
    last = fit_inplane(model, parameters, reweighted, measured, o);
    evaluations += last.evaluations;
    seconds += seconds_since(t0);  // the recording's trace and the search
    if (stage == 0) first = last;
    if (stage > 0) {
      restart_optima.emplace_back();
      for (const auto& p : last.parameters) restart_optima.back().push_back(p.value);
    }
    previous_move = moved;
    moved = largest_move(parameters, x, last);
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
  set_restart_spread(last, given, restart_optima);
  last.restarts = static_cast<int>(restart_optima.size());
  last.objective_start = first.objective_start;
  last.start_metrics = first.start_metrics;
  last.evaluations = evaluations;
  last.seconds = seconds;
  if (options.uncertainty) add_fit_uncertainty(last, reweighted, measured, options);
  return last;
}

namespace {

// Mean and sample standard deviation (NaN for fewer than two) of 'v'.
std::pair<double, double> mean_and_sd(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return {sum / static_cast<double>(v.size()), v.size() < 2 ? std::nan("") : sample_sd(v)};
}

}  // namespace

FitResult fit_over_seeds(int seeds, const FitInnerSettings& f,
                         const std::function<FitResult(const FitInnerSettings&)>& fit_at,
                         const std::function<double(const std::vector<double>&,
                                                    const FitInnerSettings&)>& objective_at) {
  if (seeds < 1) throw Error("", "--fit-seeds", "must be at least 1, not " + std::to_string(seeds));
  std::vector<FitInnerSettings> at(static_cast<size_t>(seeds), f);
  for (int k = 0; k < seeds; ++k) at[k].seed = f.seed + static_cast<uint64_t>(k);
  std::vector<FitResult> fits;
  std::vector<SeedFit> judged;
  int evaluations = 0;
  double seconds = 0;
  for (const FitInnerSettings& g : at) {
    fits.push_back(fit_at(g));
    evaluations += fits.back().evaluations;
    seconds += fits.back().seconds;
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t k = 0; k < fits.size(); ++k) {
    SeedFit s;
    s.seed = at[k].seed;
    for (const auto& p : fits[k].parameters) s.values.push_back(p.value);
    s.objective = fits[k].objective;
    s.evaluations = fits[k].evaluations;
    s.converged = fits[k].converged;
    std::vector<double> j;
    for (const FitInnerSettings& g : at) j.push_back(objective_at(s.values, g));
    evaluations += seeds;
    std::tie(s.objective_over_seeds, s.objective_over_seeds_sd) = mean_and_sd(j);
    judged.push_back(std::move(s));
  }
  size_t best = 0;
  for (size_t k = 1; k < judged.size(); ++k)
    if (judged[k].objective_over_seeds < judged[best].objective_over_seeds) best = k;
  FitResult out = std::move(fits[best]);
  for (size_t i = 0; seeds > 1 && i < out.parameters.size(); ++i) {
    std::vector<double> v;
    for (const SeedFit& s : judged) v.push_back(s.values[i]);
    out.parameters[i].seeds_lo = *std::min_element(v.begin(), v.end());
    out.parameters[i].seeds_hi = *std::max_element(v.begin(), v.end());
    out.parameters[i].sigma_seeds = mean_and_sd(v).second;
  }
  std::rotate(judged.begin(), judged.begin() + static_cast<std::ptrdiff_t>(best),
              judged.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  out.seed_fits = std::move(judged);
  out.evaluations = evaluations;
  out.seconds = seconds + seconds_since(t0);
  return out;
}

}  // namespace weft
