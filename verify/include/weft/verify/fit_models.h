#pragma once
// weft verify --fit (docs/verify.md): the physical parameters of a fiber spec that the fit may
// vary, the inner models the fit evaluates, and the fit of one model on its inner model.
#include <functional>
#include <string>
#include <vector>

#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/verify/verify.h"

namespace weft {

// ---- The spec's parameters a fit may vary ----------------------------------------------------

// One parameter, by name: its unit, its box and start for a spec (weft::Error naming the spec and
// "--fit-params" when the spec has nothing for it to vary), and how a value changes the spec.
// Scales multiply the spec's own values, so 1 is the spec as given.
struct SpecFitRule {
  struct Box {
    double lo, hi, start;
    bool log_scale;
  };
  std::string name, unit;
  std::function<Box(const FiberSpec& spec, const std::string& name)> box;
  std::function<void(FiberSpec& spec, double value)> apply;
};

// The table of the default parameters: dye_scale, particle_fraction_scale,
// particle_radius_scale, roughness_alpha. spec_fit_rule also knows dyeK_concentration (K = 0 ..
// kMaxDyeComponents - 1, the recipe's K-th concentration in % owf), named on request only.
const std::vector<SpecFitRule>& spec_fit_rules();
// The rule of that name; weft::Error naming "--fit-params" and the known names otherwise.
const SpecFitRule& spec_fit_rule(const std::string& name);

// The rules' names, in the table's order; and joined by 'separator'.
const std::vector<std::string>& spec_fit_parameter_names();
std::string spec_fit_parameter_list(const std::string& separator);

// Parses --fit-params ("a,b,..."): known names, no repeats, at most four.
std::vector<std::string> parse_spec_fit_names(const std::string& list);

// The named parameters' boxes for this spec: scales over a decade or more each way, on a log
// scale; the particles' total volume fraction stays at or below 0.5 (the spec allows 0.74 per
// species).
std::vector<FitParameter> spec_fit_parameters(const FiberSpec& spec,
                                              const std::vector<std::string>& names);

// The spec with the named parameters set to 'values'.
FiberSpec apply_spec_fit(FiberSpec spec, const std::vector<std::string>& names,
                         const std::vector<double>& values);

// The classic model's four: its diffuse colour per channel (a reflectance, on a log scale: the
// measured fabric's green and blue are an order below its red) and its roughness. A start below
// the box's floor of 0.005 starts at the floor.
std::vector<FitParameter> classic_fit_parameters(const Rgb& diffuse, double alpha);

// ---- The bakes and summations of verify, and the fit's inner models ---------------------------

// What verify's fiber bakes and paper's summations are, from its settings: one place for the run's
// bake (through the bake cache, and again for the fitted spec) and the fit's inner models. The
// run's bake is spectral (the colour table needs the spectrum) with the default weights; the fit's
// inner bake ('fit_inner') is RGB with absorption as a weight, so that at its fixed seed the table
// is a smooth function of dye_scale (transport.h, docs/verify.md). Both start from the spec's
// bake defaults (fiber_bake_defaults).
FiberTableBakeOptions verify_bake_options(const FiberSpec& spec, int resolution,
                                          uint64_t photons_per_band, uint64_t seed, int threads,
                                          bool fit_inner);
FabricSummationOptions verify_summation_options(int resolution, int samples_per_cell, uint64_t seed,
                                                int threads);

// The inner models' names, as metrics.json reports them.
std::string computed_inner_model_name(const FitInnerSettings& f);
std::string classic_inner_model_name(const FitInnerSettings& f);

// The ray-trace inner model's options: the settings' resolution, particles, seed and threads, paths
// drawn from 'proposal' when given.
FabricRaytraceOptions inner_raytrace_options(const FitInnerSettings& f,
                                             const TabulatedBsdfTable* proposal);

// The inner model's step from a fiber table to the curves, with the fixed seed. The ray trace
// draws its paths from 'proposal' when given (FabricRaytraceOptions::proposal): the fit passes the
// table of its start, so that the objective is smooth in the parameters (docs/verify.md).
std::vector<std::vector<Rgb>> inner_fabric_curves(const WovenSample& sample,
                                                  const TabulatedBsdfTable& fiber,
                                                  const FitInnerSettings& f,
                                                  const MeasuredInplane& measured,
                                                  const TabulatedBsdfTable* proposal = nullptr);

// The computed model's inner fiber table: an RGB bake with absorption as a weight, fixed seed.
TabulatedBsdfTable computed_inner_fiber_table(const FiberSpec& spec, const FitInnerSettings& f);

// The computed model's inner curves: its inner fiber table, then the inner model's step.
std::vector<std::vector<Rgb>> computed_inner_curves(const FiberSpec& spec,
                                                    const WovenSample& sample,
                                                    const FitInnerSettings& f,
                                                    const MeasuredInplane& measured,
                                                    const TabulatedBsdfTable* proposal = nullptr);

// The classic model's inner fiber table (fixed seed).
TabulatedBsdfTable classic_inner_fiber_table(const Rgb& diffuse, const MicrofacetDistribution& d,
                                             double ior, const FitInnerSettings& f);

// The classic model's inner curves: its fiber table, then the same step.
std::vector<std::vector<Rgb>> classic_inner_curves(const Rgb& diffuse,
                                                   const MicrofacetDistribution& d, double ior,
                                                   const WovenSample& sample,
                                                   const FitInnerSettings& f,
                                                   const MeasuredInplane& measured,
                                                   const TabulatedBsdfTable* proposal = nullptr);

// ---- The fit of one model ----------------------------------------------------------------------

// The fit of one model on its inner model. 'table_of' makes the model's inner fiber table for a
// parameter vector. With the ray-trace inner model the particles draw their paths from a proposal
// table (FabricRaytraceOptions::proposal), so that at the fixed seed the objective is smooth in
// the parameters: first the start's table; the reweighted estimate's noise grows with the distance
// from the proposal, so the proposal is then re-centred on the optimum and the search restarted
// there, until a search converges without moving more than 1 % of any box (in the search's unit
// cube) from its proposal's point, or the evaluations are spent (options.max_evaluations over
// all stages; the uncertainty, computed once at the last stage's optimum with its proposal, adds
// 2 p + 1). The result: the last stage's optimum and uncertainty, the first's start, the
// evaluations and seconds of all. Each proposal's paths are traced once and re-weighted for every
// evaluation's table (recorded_paths.h): the bits of tracing each table with the proposal.
FitResult fit_inner_model(
    const std::string& model, std::vector<FitParameter> parameters,
    const std::function<TabulatedBsdfTable(const std::vector<double>&)>& table_of,
    const WovenSample& sample, const FitInnerSettings& f, const MeasuredInplane& measured,
    const FitOptions& options);

// The fit at 'seeds' inner seeds, f.seed, f.seed + 1, ... (--fit-seeds): each another
// realization of the inner model's noise, which a fit at one seed cannot tell from the
// measurement's. fit_at(g) fits at g.seed (verify's from the start fit_start_of(.., g.seed -
// f.seed)); objective_at(x, g) is the inner rms_log of parameters x
// at g.seed, without a proposal. Each fit's optimum is judged by its objective averaged over every
// seed's inner model (seeds^2 evaluations), and the best judged is returned (its seed_fits list
// every fit, the chosen first), with each parameter's spread over the fits (seeds_lo, seeds_hi,
// sigma_seeds), the evaluations and seconds of all. weft::Error for seeds < 1.
FitResult fit_over_seeds(
    int seeds, const FitInnerSettings& f,
    const std::function<FitResult(const FitInnerSettings&)>& fit_at,
    const std::function<double(const std::vector<double>&, const FitInnerSettings&)>& objective_at);

}  // namespace weft
