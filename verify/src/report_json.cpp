// metrics.json of the report (docs/verify.md gives its keys).
#include <cmath>
#include <nlohmann/json.hpp>

#include "common.h"
#include "weft/verify/models.h"
#include "weft/verify/report.h"

namespace weft {
namespace {

nlohmann::json metrics_json(const CurveMetrics& m) {
  return {{"rms_log", m.rms_log},
          {"rms_rel", m.rms_rel},
          {"points", m.points},
          {"excluded", m.excluded}};
}

nlohmann::json rgb_json(const Rgb& c) {
  return nlohmann::json::array({c.r, c.g, c.b});
}

nlohmann::json settings_json(const VerifySettings& s) {
  return {{"quality", quality_name(s.quality)},
          {"resolution", s.resolution},
          {"fiber_photons_per_band", s.fiber_photons_per_band},
          {"particles_per_bin", s.particles_per_bin},
          {"batches", s.batches},
          {"summation_samples", s.summation_samples},
          {"azimuths", s.azimuths},
          {"render_size", s.render_size},
          {"render_spp", s.render_spp},
          {"weave_render_size", s.weave_render_size},
          {"weave_render_spp", s.weave_render_spp},
          {"threads", s.threads}};
}

// A number, or null where it is not defined.
nlohmann::json number_json(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json shape_json(const ShapeFigure& s, const MeasuredInplane& measured) {
  nlohmann::json per = nlohmann::json::array();
  for (size_t i = 0; i < s.rms_log_incidence.size(); ++i)
    per.push_back({{"theta_i_deg", measured.curves[i].theta_i_deg},
                   {"rms_log", number_json(s.rms_log_incidence[i])}});
  nlohmann::json channels = nlohmann::json::object();
  for (int k = 0; k < 3; ++k)
    channels[std::string(1, "RGB"[k])] = number_json(s.rms_log_channel[k]);
  return {{"rms_log", number_json(s.rms_log)},
          {"gain", {number_json(s.gain.r), number_json(s.gain.g), number_json(s.gain.b)}},
          {"max_view_deg", kShapeMaxViewDeg},
          {"points", s.points},
          {"rms_log_channel", channels},
          {"per_incidence", per},
          {"rms_log_beyond_max_view", number_json(s.rms_log_grazing)},
          {"points_beyond_max_view", s.grazing_points},
          {"excluded", s.excluded}};
}

// A figure with its uncertainty: the seed's (batches) and the measurement's (its fits).
nlohmann::json figure_json(const FigureSamples& f, const std::vector<std::string>& fits,
                           bool comparable) {
  nlohmann::json per_fit = nlohmann::json::object(), per_batch = nlohmann::json::array();
  for (size_t k = 0; k < fits.size(); ++k) per_fit[fits[k]] = number_json(f.mean[k]);
  if (!f.batch.empty())
    for (double v : f.batch[0]) per_batch.push_back(number_json(v));
  return {{"value", number_json(f.value())},
          {"batches", per_batch.size()},
          {"per_batch", per_batch},
          {"seed_sd", number_json(f.seed_sd())},
          {"seed_se", number_json(f.seed_se())},
          {"per_fit", per_fit},
          {"fit_min", number_json(f.fit_min())},
          {"fit_max", number_json(f.fit_max())},
          {"comparable", comparable}};
}

nlohmann::json uncertainty_json(const ModelFigures& f, bool absolute_is_judged) {
  nlohmann::json u = {{"fits", f.fits}};
  if (f.fits.empty()) return u;
  for (int k = 0; k < 3; ++k)
    u[kFigureKeys[k]] =
        figure_json(f.figure[k], f.fits, k != kAbsoluteFigure || absolute_is_judged);
  return u;
}

// Per model: its metrics overall, per incidence and per incidence and channel.
nlohmann::json models_json(const VerifyReport& r) {
  nlohmann::json models = nlohmann::json::object();
  for (const auto& m : r.models) {
    nlohmann::json per = nlohmann::json::array();
    for (size_t i = 0; i < r.measured.curves.size(); ++i) {
      nlohmann::json channels = nlohmann::json::object();
      if (i < m.absolute_channel.size())
        for (int k = 0; k < 3; ++k)
          channels[std::string(1, "RGB"[k])] = {
              {"absolute", metrics_json(m.absolute_channel[i][k])},
              {"normalized", metrics_json(m.normalized_channel[i][k])}};
      per.push_back({{"theta_i_deg", r.measured.curves[i].theta_i_deg},
                     {"absolute", metrics_json(m.absolute[i])},
                     {"normalized", metrics_json(m.normalized[i])},
                     {"channels", channels}});
    }
    models[m.key] = {{"label", m.label},
                     {"normalization_factor", rgb_json(m.normalization)},
                     {"absolute", metrics_json(m.absolute_overall)},
                     {"normalized", metrics_json(m.normalized_overall)},
                     {"per_incidence", per},
                     {"uncertainty", uncertainty_json(m.figures, absolute_judged(r))},
                     {"log_floored_points", m.figures.log_floored_points}};
    if (!m.figures.fits.empty()) models[m.key]["shape"] = shape_json(m.figures.shape, r.measured);
    // Calibrated (--colour-from measured): every unfitted model is made of the fiber dyed to the
    // measurement's own d/8 reading, so its absolute figure has had that one calibration and no
    // per-channel gain; the fitted models set their colour themselves and have none.
    if (r.colour_calibrated && !is_fitted_model(m.key))
      models[m.key]["calibrated"] = metrics_json(m.absolute_overall);
  }
  return models;
}

// The headline figures at the top level: computed is the fiber-level ray trace.
void add_headline_figures(nlohmann::json& j, const std::vector<ModelCurves>& models,
                          bool calibrated) {
  for (const auto& m : models)
    for (const VerifyModelNames& names : kVerifyModels)
      if (m.key == names.key && !m.figures.fits.empty()) {
        const char* name = names.headline;
        const ShapeFigure& s = m.figures.shape;
        j[std::string(name) + "_shape_rms_log"] = number_json(s.rms_log);
        j[std::string(name) + "_shape_gain"] = {number_json(s.gain.r), number_json(s.gain.g),
                                                number_json(s.gain.b)};
      }
  for (const auto& m : models) {
    if (m.key == verify_model_key(VerifyModel::kComputedRaytrace)) {
      j["computed_rms_log"] = m.normalized_overall.rms_log;
      j["computed_rms_log_absolute"] = m.absolute_overall.rms_log;
      // Calibrated to the measurement's own d/8 reading, the absolute figure is the calibrated
      // one: no per-channel gain after that one reading.
      if (calibrated) j["computed_calibrated_rms_log"] = m.absolute_overall.rms_log;
      j["computed_rms_rel"] = m.normalized_overall.rms_rel;
      j["computed_rms_rel_absolute"] = m.absolute_overall.rms_rel;
    }
    if (m.key == verify_model_key(VerifyModel::kComputedRaytraceFitted)) {
      j["computed_fitted_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["computed_fitted_rms_log"] = m.normalized_overall.rms_log;
    }
    if (m.key == verify_model_key(VerifyModel::kClassicFitted)) {
      j["classic_fitted_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["classic_fitted_rms_log"] = m.normalized_overall.rms_log;
    }
    if (m.key == verify_model_key(VerifyModel::kClassic)) {
      j["classic_rms_log"] = m.normalized_overall.rms_log;
      j["classic_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["classic_rms_rel"] = m.normalized_overall.rms_rel;
      j["classic_rms_rel_absolute"] = m.absolute_overall.rms_rel;
    }
  }
}

nlohmann::json fit_parameters_json(const FitResult& f) {
  nlohmann::json ps = nlohmann::json::array();
  for (const auto& p : f.parameters)
    ps.push_back({{"name", p.parameter.name},
                  {"unit", p.parameter.unit},
                  {"start", p.parameter.start},
                  {"lo", p.parameter.lo},
                  {"hi", p.parameter.hi},
                  {"log_scale", p.parameter.log_scale},
                  {"value", p.value},
                  {"sigma", std::isfinite(p.sigma) ? nlohmann::json(p.sigma) : nlohmann::json()},
                  {"sigma_restarts", number_json(p.sigma_restarts)},
                  {"seeds_lo", number_json(p.seeds_lo)},
                  {"seeds_hi", number_json(p.seeds_hi)},
                  {"sigma_seeds", number_json(p.sigma_seeds)},
                  {"at_bound", p.at_bound}});
  return ps;
}

// The fits at each inner seed (fit_over_seeds), the chosen one first.
nlohmann::json seed_fits_json(const FitResult& f) {
  nlohmann::json out = nlohmann::json::array();
  for (const SeedFit& s : f.seed_fits)
    out.push_back({{"seed", s.seed},
                   {"values", s.values},
                   {"inner_rms_log", s.objective},
                   {"inner_rms_log_over_seeds", s.objective_over_seeds},
                   {"inner_rms_log_over_seeds_sd", number_json(s.objective_over_seeds_sd)},
                   {"evaluations", s.evaluations},
                   {"converged", s.converged}});
  return out;
}

// One fit: its parameters, its search, and the fitted model at the run's quality.
nlohmann::json fit_json(const FitResult& f, const std::vector<ModelCurves>& models) {
  nlohmann::json e = {{"parameters", fit_parameters_json(f)},
                      {"inner_model", f.inner_model},
                      {"method", f.method},
                      {"uncertainty", f.uncertainty},
                      {"objective", "rms_log, absolute, of the inner model"},
                      {"inner_rms_log_start", f.objective_start},
                      {"inner_rms_log_fitted", f.objective},
                      {"inner_start", metrics_json(f.start_metrics)},
                      {"inner_fitted", metrics_json(f.fitted_metrics)},
                      {"evaluations", f.evaluations},
                      {"restarts", f.restarts},
                      {"converged", f.converged},
                      {"seeds", seed_fits_json(f)},
                      {"seconds", f.seconds}};
  // The fitted parameters at the run's quality (the same ray trace as the unfitted curves).
  const std::string key = f.model == "computed"
                              ? verify_model_key(VerifyModel::kComputedRaytraceFitted)
                              : f.model + kFittedKeySuffix;
  for (const auto& m : models)
    if (m.key == key)
      e["at_run_quality"] = {{"model", key},
                             {"absolute", metrics_json(m.absolute_overall)},
                             {"normalized", metrics_json(m.normalized_overall)}};
  return e;
}

nlohmann::json verdict_json(const VerifyReport& r) {
  nlohmann::json v = {
      {"rule",
       "a is closer when its figure is below b's; resolved when the difference a - b has "
       "one sign against every fit of the measurement and for every batch, exceeds " +
           fmt(kVerdictSeedErrors, 2) +
           " seed standard errors (paired batch differences) against every fit, and exceeds the "
           "measurement's own spread (measured_spread: the largest figure between two of its "
           "fits; with one fit, spread unknown, min_bundled_fit_spread) against every fit; "
           "otherwise a tie. Where every model's shape rms_log is above no_model_shape_rms_log, "
           "no model describes the sample and none is named closer"}};
  const VerifyVerdictContext context = verify_verdict_context(r);
  nlohmann::json spread = nlohmann::json::object(), floor = nlohmann::json::object();
  for (int k = 0; k < 3; ++k) {
    spread[kFigureKeys[k]] = number_json(context.measured_spread[k]);
    floor[kFigureKeys[k]] = kMinBundledFitSpread[k];
  }
  v["measured_spread"] = spread;
  v["min_bundled_fit_spread"] = floor;
  v["no_model_shape_rms_log"] = kNoModelShapeRmsLog;
  v["no_model_describes"] = context.no_model_describes;
  for (const char* key : kFigureKeys) v[key] = nlohmann::json::array();
  for (const Verdict& d : verify_verdicts(r)) {
    nlohmann::json per_fit = nlohmann::json::array();
    for (double x : d.difference_per_fit) per_fit.push_back(number_json(x));
    v[d.figure].push_back({{"a", d.a},
                           {"b", d.b},
                           {"a_value", number_json(d.a_value)},
                           {"b_value", number_json(d.b_value)},
                           {"difference", number_json(d.difference)},
                           {"difference_seed_se", number_json(d.difference_seed_se)},
                           {"difference_per_fit", per_fit},
                           {"same_sign_fits", d.same_sign_fits},
                           {"same_sign_batches", d.same_sign_batches},
                           {"exceeds_seed", d.exceeds_seed},
                           {"measured_spread", number_json(d.measured_spread)},
                           {"spread_required", number_json(d.spread_required)},
                           {"exceeds_spread", d.exceeds_spread},
                           {"resolved", d.resolved},
                           {"tie", d.tie},
                           {"no_model_describes", d.no_model_describes},
                           {"comparable", d.comparable},
                           {"closer", d.resolved ? nlohmann::json(d.closer) : nlohmann::json()},
                           {"text", d.text}});
  }
  return v;
}

nlohmann::json colours_json(const std::vector<ColourEntry>& entries) {
  nlohmann::json colours = nlohmann::json::array();
  for (const auto& c : entries) {
    nlohmann::json e = {{"name", c.name}, {"hsv", {c.hsv.h, c.hsv.s, c.hsv.v}}, {"note", c.note}};
    if (std::isfinite(c.rgb.r)) {
      if (c.colour_space == "linear sRGB")
        e["linear_srgb"] = rgb_json(c.rgb);
      else
        e["rgb"] = rgb_json(c.rgb);
    }
    e["colour_space"] = c.colour_space;
    e["comparable"] = c.comparable;
    if (c.spectrum) e["spectrum"] = *c.spectrum;
    colours.push_back(e);
  }
  return colours;
}

nlohmann::json renders_json(const std::vector<VerifyRender>& images) {
  nlohmann::json renders = nlohmann::json::array();
  for (const auto& v : images) {
    nlohmann::json e = {{"kind", v.kind},
                        {"model", v.model},
                        {"configuration", v.configuration},
                        {"exr", v.stem + ".exr"},
                        {"png", v.stem + ".png"},
                        {"caption", v.caption},
                        {"mean_linear_srgb", rgb_json(v.mean)}};
    if (v.kind == "patch") e["patch_radiance_linear_srgb"] = rgb_json(v.patch_radiance);
    renders.push_back(e);
  }
  return renders;
}

}  // namespace

nlohmann::json verify_metrics(const VerifyReport& r) {
  nlohmann::json j;
  j["report"] = "weft verify";
  j["measured"] = r.measured.file;
  // The measurement's RGB space, and whether the figures that include the colour's level (the
  // absolute ones, the colour table's absolute colour) compare with the models' linear sRGB.
  j["colour_space"] = colour_space_name(r.measured.colour_space);
  j["absolute_comparable"] = absolute_judged(r);
  if (!absolute_judged(r))
    j["absolute_note"] =
        not_comparable_note(r.measured.colour_space) +
        "; the shape and the paper's normalized figures stay comparable (per-channel "
        "gains absorb the diagonal part of a change of RGB space)";
  j["fiber"] = r.fiber_name;
  if (!r.colour_match.is_null()) j["colour_match"] = r.colour_match;
  // --colour-from measured: the absolute figures are the calibrated ones (computed_calibrated_*).
  j["colour_calibrated"] = r.colour_calibrated;
  j["sample"] = r.sample_name;
  const VerifySettings& s = r.settings;
  j["settings"] = settings_json(s);
  j["seed"] = s.seed;
  j["seconds"] = r.seconds;
  j["normalization"] =
      "paper (section 4): per model and channel, beta scaled so that beta at normal incidence and "
      "view equals the measured one";
  j["metrics"] =
      "rms_log: RMS of ln(model / measured); rms_rel: RMS of (model - measured) / "
      "measured; over every view, incidence and channel, each side's channel floored at "
      "log_floor_fraction of its own maximum (linear sRGB is kept unclamped, so a saturated "
      "colour has negative components: log_floored_points per model, measured_log_floored_points "
      "for the reference fit); a channel with no positive value is excluded";
  j["log_floor_fraction"] = kLogFloorFraction;
  j["measured_log_floored_points"] =
      r.measured.curves.empty() ? 0 : floor_for_log(measured_fits(r.measured).front().beta).floored;
  j["shape"] =
      "per model and channel one gain, ln g = mean of ln(measured / model) over the points where "
      "both are positive and |view| <= " +
      fmt(kShapeMaxViewDeg, 3) +
      " deg; rms_log of g model against measured over those points (the views beyond: "
      "rms_log_beyond_max_view, the same gains)";
  j["uncertainty"] =
      "per figure: seed_sd, the standard deviation of the figure over the ray trace's batches "
      "(each an independent seed), and seed_se = seed_sd / sqrt(batches), the standard error of "
      "the figure of their mean (shown after +-); per_fit, the figure against each fit of the "
      "measurement (fit_min..fit_max: how far the figure moves with the reference; the verdict's "
      "measured_spread is the figure between the measurement's fits themselves)";
  j["models"] = models_json(r);
  add_headline_figures(j, r.models, r.colour_calibrated);
  j["verdict"] = verdict_json(r);
  if (!r.fits.empty()) {
    nlohmann::json fit = nlohmann::json::object();
    for (const auto& f : r.fits) fit[f.model] = fit_json(f, r.models);
    j["fit"] = fit;
  }
  j["colour_table"] = colours_json(r.colours);
  j["renders"] = renders_json(r.renders);
  j["render_setup"] = kVerifyRenderSetup;
  j["weave_render_setup"] = kVerifyWeaveRenderSetup;
  j["classic_reflectance_linear_srgb"] = rgb_json(r.classic_reflectance);
  j["classic_reflectance_clipped_components"] = r.classic_clip.components;
  j["classic_source"] = r.classic_source;
  j["fabric_table_gamut_clipped_components"] = r.fabric_table_gamut_clipped;
  j["fabric_table_out_of_gamut_components"] = r.fabric_table_out_of_gamut.components;
  j["fabric_table_out_of_gamut_largest"] = r.fabric_table_out_of_gamut.largest;
  j["raytrace_relative_noise"] = r.raytrace_relative_noise;
  return j;
}

std::string verify_metrics_json(const VerifyReport& r) {
  return verify_metrics(r).dump(2) + "\n";
}

}  // namespace weft
