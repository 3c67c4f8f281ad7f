// weft verify --fit: both models fitted on their inner models, then evaluated at the run's quality
// (whole_run.h).
#include <chrono>

#include "common.h"
#include "weft/verify/fit_models.h"
#include "weft/verify/models.h"
#include "weft/verify/whole_run.h"

namespace weft {

namespace {

// The fitted parameters at the run's quality: the computed model's spec baked again, the classic
// model's colour and roughness, both through run_verify. Nullopt when interrupted.
std::optional<VerifyReport> fitted_at_run_quality(const VerifyPlan& p, const WovenSample& sample,
                                                  const VerifyInputs& base,
                                                  const FitResult& computed,
                                                  const FitResult& classic,
                                                  const ProgressCallback& progress) {
  const VerifySettings& s = p.settings;
  std::vector<double> values;
  for (const auto& fp : computed.parameters) values.push_back(fp.value);
  const FiberSpec fitted = apply_spec_fit(p.spec, p.fit_names, values);
  VerifyInputs in;
  in.fiber_name = base.fiber_name + " (fitted)";
  in.sample_name = base.sample_name;
  const FiberTableBakeOptions b =
      verify_bake_options(fitted, s.resolution, s.fiber_photons_per_band, s.seed, s.threads, false);
  FiberTableBakeResult fiber = bake_fiber_table(fitted, b, progress);
  if (fiber.cancelled) return std::nullopt;
  for (const auto& band : fiber.bands)
    in.volume_albedo[band.band] = band.exit_fraction - band.surface_fraction;
  in.fiber = std::move(fiber.table);
  in.classic_distribution = {base.classic_distribution.model, classic.parameters[3].value};
  in.classic_ior = base.classic_ior;
  in.classic_diffuse =
      Rgb(classic.parameters[0].value, classic.parameters[1].value, classic.parameters[2].value);
  VerifyReport again = run_verify(sample, in, p.measured, s, progress);
  if (again.cancelled) return std::nullopt;
  return again;
}

// Thrown from inside a fit when the user interrupts: a fit in progress has nothing to keep, and
// its inner bakes take no progress callback, so the fit checks between its evaluations.
struct FitInterrupted {};
void stop_if_interrupted(const VerifyHooks& hooks) {
  if (hooks.interrupted()) throw FitInterrupted{};
}

// A fit at one inner seed, announced before and summed up after (a fit takes tens of seconds).
FitResult noted_fit(const VerifyPlan& p, const FitInnerSettings& g, const FitInnerSettings& first,
                    const VerifyHooks& hooks, const std::function<FitResult()>& fit) {
  const uint64_t k = g.seed - first.seed + 1;
  hooks.note("  inner seed " + std::to_string(g.seed) + " (" + std::to_string(k) + " of " +
             std::to_string(p.fit_seeds) + ")");
  FitResult r = fit();
  hooks.note(": inner rms_log " + fmt(r.objective, 4) + " after " + std::to_string(r.evaluations) +
             " evaluations, " + fmt(r.seconds, 3) + " s" + (r.converged ? "" : ", not converged") +
             "\n");
  return r;
}

// A model's inner fiber table for parameters x at the inner settings g.
using InnerTable =
    std::function<TabulatedBsdfTable(const std::vector<double>& x, const FitInnerSettings& g)>;

// One model fitted at the plan's inner seeds, each fit from its own start (fit_over_seeds,
// fit_start_of); its optima judged by the same inner model at every seed, without a proposal.
FitResult fit_model(const VerifyPlan& p, const std::string& model,
                    const std::vector<FitParameter>& params, const InnerTable& table_of,
                    const WovenSample& sample, const FitInnerSettings& inner,
                    const VerifyHooks& hooks) {
  const MeasuredInplane& measured = p.measured;
  return fit_over_seeds(
      p.fit_seeds, inner,
      [&](const FitInnerSettings& g) {
        return noted_fit(p, g, inner, hooks, [&] {
          return fit_inner_model(
              model, fit_start_of(params, static_cast<int>(g.seed - inner.seed)),
              [&](const std::vector<double>& x) {
                stop_if_interrupted(hooks);
                return table_of(x, g);
              },
              sample, g, measured, p.fit_options);
        });
      },
      [&](const std::vector<double>& x, const FitInnerSettings& g) {
        stop_if_interrupted(hooks);
        return fit_rms_log(inner_fabric_curves(sample, table_of(x, g), g, measured), measured);
      });
}

// Which seed's fit was kept, and its objective over every seed (fit_over_seeds judges by it).
void note_kept(const VerifyHooks& hooks, const FitResult& r) {
  if (r.seed_fits.size() < 2) return;
  const SeedFit& kept = r.seed_fits.front();
  hooks.note("  kept seed " + std::to_string(kept.seed) + ": inner rms_log over the seeds " +
             fmt(kept.objective_over_seeds, 4) + " +- " + fmt(kept.objective_over_seeds_sd, 2) +
             "\n");
}

// What the inner model's name adds for a fit at several seeds.
std::string seeds_note(const VerifyPlan& p, const FitInnerSettings& inner) {
  if (p.fit_seeds < 2) return "";
  return "; fitted at seeds " + std::to_string(inner.seed) + " to " +
         std::to_string(inner.seed + static_cast<uint64_t>(p.fit_seeds) - 1) +
         ", the fit whose optimum is best over all of them kept";
}

}  // namespace

bool fit_verify_models(const VerifyPlan& p, const WovenSample& sample, const VerifyInputs& base,
                       VerifyReport& report, const VerifyHooks& hooks) {
  FitInnerSettings inner = fit_inner_settings(p.settings);
  inner.inner = p.fit_inner;
  FitResult computed, classic;
  try {
    hooks.note("\nweft: fitting the computed model (" + p.request.fiber + ")\n");
    computed = fit_model(
        p, "computed", spec_fit_parameters(p.spec, p.fit_names),
        [&](const std::vector<double>& x, const FitInnerSettings& g) {
          return computed_inner_fiber_table(apply_spec_fit(p.spec, p.fit_names, x), g);
        },
        sample, inner, hooks);
    note_kept(hooks, computed);
    hooks.note("weft: fitting the classic model\n");
    const MicrofacetDistribution& start = base.classic_distribution;
    const double ior = base.classic_ior;
    classic = fit_model(
        p, "classic", classic_fit_parameters(report.classic_reflectance, start.alpha),
        [&](const std::vector<double>& x, const FitInnerSettings& g) {
          return classic_inner_fiber_table(Rgb(x[0], x[1], x[2]), {start.model, x[3]}, ior, g);
        },
        sample, inner, hooks);
    note_kept(hooks, classic);
  } catch (const FitInterrupted&) {
    return false;
  }
  computed.inner_model = computed_inner_model_name(inner) + seeds_note(p, inner);
  classic.inner_model = classic_inner_model_name(inner) + seeds_note(p, inner);

  const auto t0 = std::chrono::steady_clock::now();
  const std::optional<VerifyReport> again =
      fitted_at_run_quality(p, sample, base, computed, classic, hooks.progress);
  if (!again) return false;
  for (ModelCurves m : again->models) {
    m.key += kFittedKeySuffix;
    m.label += ", fitted";
    report.models.push_back(std::move(m));
  }
  report.seconds["fit_computed"] = computed.seconds;
  report.seconds["fit_classic"] = classic.seconds;
  report.seconds["fit_at_run_quality"] = seconds_since(t0);
  report.fits = {std::move(computed), std::move(classic)};
  return true;
}

}  // namespace weft
