// weft verify --fit: both models fitted on their inner models, then evaluated at the run's quality
// (whole_run.h).
#include <chrono>

#include "common.h"
#include "weft/verify/fit_models.h"
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

}  // namespace

bool fit_verify_models(const VerifyPlan& p, const WovenSample& sample, const VerifyInputs& base,
                       VerifyReport& report, const VerifyHooks& hooks) {
  const MeasuredInplane& measured = p.measured;
  FitInnerSettings inner = fit_inner_settings(p.settings);
  inner.inner = p.fit_inner;
  hooks.note("\nweft: fitting the computed model (" + p.request.fiber + ")\n");
  FitResult computed = fit_inner_model(
      "computed", spec_fit_parameters(p.spec, p.fit_names),
      [&](const std::vector<double>& x) {
        return computed_inner_fiber_table(apply_spec_fit(p.spec, p.fit_names, x), inner);
      },
      sample, inner, measured, p.fit_options);
  computed.inner_model = computed_inner_model_name(inner);
  hooks.note("weft: fitting the classic model\n");
  const MicrofacetModel model = base.classic_distribution.model;
  FitResult classic = fit_inner_model(
      "classic",
      classic_fit_parameters(report.classic_reflectance, base.classic_distribution.alpha),
      [&](const std::vector<double>& x) {
        return classic_inner_fiber_table(Rgb(x[0], x[1], x[2]), {model, x[3]}, base.classic_ior,
                                         inner);
      },
      sample, inner, measured, p.fit_options);
  classic.inner_model = classic_inner_model_name(inner);

  const auto t0 = std::chrono::steady_clock::now();
  const std::optional<VerifyReport> again =
      fitted_at_run_quality(p, sample, base, computed, classic, hooks.progress);
  if (!again) return false;
  for (ModelCurves m : again->models) {
    m.key += "_fitted";
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
