#include "weft/verify/run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <system_error>

#include "common.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/materials/classic_fiber.h"
#include "weft/verify/classic.h"
#include "weft/verify/inplane.h"
#include "weft/verify/models.h"

namespace weft {
namespace {

// Batch k of a model's ray trace: its own stream, from the run's seed (core/hash.h).
uint64_t batch_seed(uint64_t seed, const std::string& model, int k) {
  return fnv1a64(model + ":" + std::to_string(seed) + ":" + std::to_string(k));
}

// Ray-traced fabric table of 'fiber' in 'batches' independent runs: the curves of their mean and
// the standard error of that mean from their spread (what the error bars show).
struct TracedCurves {
  InplaneCurves beta, err;
  std::vector<InplaneCurves> batches;  // each batch's curves
  TabulatedBsdfTable mean;             // the fiber table's channels
  double relative_noise = 0;
  bool cancelled = false;
};

FabricRaytraceOptions trace_options(const VerifySettings& s, const std::string& model, int k) {
  FabricRaytraceOptions o;
  o.resolution = s.resolution;
  o.particles_per_bin = s.particles_per_bin / static_cast<uint64_t>(s.batches);
  o.seed = batch_seed(s.seed, model, k);
  o.threads = s.threads;
  return o;
}

TracedCurves trace_curves(const WovenSample& sample, const TabulatedBsdfTable& fiber,
                          const MeasuredInplane& measured, const VerifySettings& s,
                          const std::string& model, const ProgressCallback& progress,
                          const VerifyTraced* traced) {
  TracedCurves out;
  const size_t n_inc = measured.curves.size();
  std::vector<InplaneCurves>& per_batch = out.batches;
  std::vector<double> sum;
  double noise2 = 0;
  for (int k = 0; k < s.batches; ++k) {
    FabricRaytraceResult here;
    const FabricRaytraceResult* found = nullptr;
    if (traced)
      if (const auto it = traced->find({model, k}); it != traced->end()) found = &it->second;
    if (!found) {
      here = raytrace_fabric_table(sample, fiber, trace_options(s, model, k), progress);
      found = &here;
    }
    const FabricRaytraceResult& r = *found;
    if (r.table.channels != fiber.channels || r.table.resolution != s.resolution)
      throw Error("", model, "a ray trace handed in is of another table");
    if (r.cancelled) {
      out.cancelled = true;
      return out;
    }
    noise2 += r.relative_noise * r.relative_noise;
    if (sum.empty()) {
      sum.assign(r.table.values.size(), 0.0);
      out.mean = r.table;
    }
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += r.table.values[i];
    const TableReader rgb = table_to_rgb(TableReader(r.table, s.threads));
    auto& curves = per_batch.emplace_back();
    for (const auto& c : measured.curves)
      curves.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, s.azimuths));
  }
  for (size_t i = 0; i < sum.size(); ++i)
    out.mean.values[i] = static_cast<float>(sum[i] / s.batches);
  // Each batch's noise is sqrt(batches) times the mean's.
  out.relative_noise = std::sqrt(noise2 / s.batches) / std::sqrt(double(s.batches));
  out.beta.resize(n_inc);
  out.err.resize(n_inc);
  const double kb = s.batches;
  for (size_t i = 0; i < n_inc; ++i) {
    const size_t nv = measured.curves[i].view_deg.size();
    out.beta[i].assign(nv, Rgb());
    out.err[i].assign(nv, Rgb());
    for (size_t v = 0; v < nv; ++v) {
      Rgb m, m2;
      for (const auto& b : per_batch) {
        m += b[i][v];
        m2 += b[i][v] * b[i][v];
      }
      m = m / kb;
      Rgb var = m2 / kb + m * m * -1.0;  // population variance of the batches
      Rgb err;
      for (int c = 0; c < 3; ++c) {
        const double sd2 = std::max(0.0, var[c]) * kb / std::max(1.0, kb - 1);
        (c == 0 ? err.r : c == 1 ? err.g : err.b) = std::sqrt(sd2 / kb);
      }
      out.beta[i][v] = m;
      out.err[i][v] = err;
    }
  }
  return out;
}

ModelCurves model_curves(std::string key, std::string label, InplaneCurves beta, InplaneCurves err,
                         std::vector<InplaneCurves> batches = {}) {
  ModelCurves m;
  m.key = std::move(key);
  m.label = std::move(label);
  m.beta = std::move(beta);
  m.beta_err = std::move(err);
  m.batch_beta = std::move(batches);
  return m;
}

void score(ModelCurves& m, const MeasuredInplane& meas, const MeasuredCurve& normal_curve,
           size_t normal_view) {
  const size_t normal_incidence = static_cast<size_t>(&normal_curve - meas.curves.data());
  // Log metrics of values floored at a fraction of each channel's maximum (figures.h
  // kLogFloorFraction): an out-of-gamut channel is kept negative, not clipped, in the curves.
  const InplaneCurves model = floor_for_log(m.beta).curves;
  const InplaneCurves reference = floor_for_log(measured_fits(meas).front().beta).curves;
  const Rgb model0 = model[normal_incidence][normal_view];
  m.normalization = paper_normalization(model0, reference[normal_incidence][normal_view]);
  // Without a factor in every channel the paper's figure is not defined (as in figures.h).
  const bool normalized = std::isfinite(m.normalization.r) && std::isfinite(m.normalization.g) &&
                          std::isfinite(m.normalization.b);
  m.figures = model_figures(m.beta, m.batch_beta, meas, {normal_incidence, normal_view});
  MetricsAccumulator abs_all, norm_all;
  for (size_t i = 0; i < meas.curves.size(); ++i) {
    MetricsAccumulator a, n;
    std::array<MetricsAccumulator, 3> ac, nc;
    for (size_t v = 0; v < reference[i].size(); ++v)
      for (int k = 0; k < 3; ++k) {
        ac[k].add(model[i][v][k], reference[i][v][k]);
        nc[k].add(model[i][v][k] * m.normalization[k], reference[i][v][k]);
      }
    auto& acm = m.absolute_channel.emplace_back();
    auto& ncm = m.normalized_channel.emplace_back();
    for (int k = 0; k < 3; ++k) {
      a.add(ac[k]);
      n.add(nc[k]);
      acm[k] = ac[k].result();
      ncm[k] = nc[k].result();
    }
    m.absolute.push_back(a.result());
    m.normalized.push_back(normalized ? n.result() : MetricsAccumulator{}.result());
    abs_all.add(a);
    norm_all.add(n);
  }
  m.absolute_overall = abs_all.result();
  m.normalized_overall = normalized ? norm_all.result() : MetricsAccumulator{}.result();
}

// Where the measurement has normal incidence and normal view.
struct NormalPoint {
  const MeasuredCurve* curve = nullptr;
  size_t view = 0;
};

// The settings and inputs a run needs, and the measurement's normal point (the paper's
// normalization needs it).
NormalPoint check_run(const VerifyInputs& in, const MeasuredInplane& measured,
                      const VerifySettings& s) {
  if (s.batches < 2) throw Error("", "batches", "the error bars need at least 2 batches");
  if (s.particles_per_bin < static_cast<uint64_t>(s.batches))
    throw Error("", "particles_per_bin", "fewer particles than batches");
  if (in.fiber.resolution != s.resolution)
    throw Error("", "fiber.resolution", "the fiber table's resolution differs from the settings'");
  const std::optional<NormalIndex> normal = normal_index(measured);
  if (!normal)
    throw Error(measured.file, "theta_i_deg",
                "no row at theta_i_deg = 0, theta_o_deg = 0 (the paper's normalization needs it)");
  return {&measured.curves[normal->incidence], normal->view};
}

// The computed fabric's ray trace in the report: its curves, noise, table and fiber table.
void add_computed_raytrace(VerifyReport& rep, const TracedCurves& computed, const VerifyInputs& in,
                           const WovenSample& sample) {
  rep.raytrace_relative_noise = computed.relative_noise;
  // Nothing is clipped (table_to_rgb keeps negative components); what lies outside the gamut is
  // counted.
  table_to_rgb(computed.mean, &rep.fabric_table_out_of_gamut);
  rep.fabric_table_gamut_clipped = 0;
  rep.models.push_back(model_curves(verify_model(VerifyModel::kComputedRaytrace).key,
                                    verify_model(VerifyModel::kComputedRaytrace).label,
                                    computed.beta, computed.err, computed.batches));
  rep.computed_fabric = computed.mean;
  rep.computed_fiber = in.fiber;
  if (sample.fibers.curve_count() > 0) rep.sample = std::make_shared<const WovenSample>(sample);
}

// The paper's summation (deterministic up to its stratified cell sampling): no error bars.
ModelCurves summation_curves(const TabulatedBsdfTable& summation, const MeasuredInplane& measured,
                             int azimuths) {
  const TableReader rgb = table_to_rgb(TableReader(summation));
  ModelCurves m = model_curves(verify_model(VerifyModel::kComputedSummation).key,
                               verify_model(VerifyModel::kComputedSummation).label, {}, {});
  for (const auto& c : measured.curves) {
    m.beta.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, azimuths));
    m.beta_err.emplace_back(c.view_deg.size(), Rgb());
  }
  return m;
}

// The measured BRDF's neural fit, where the measurement has one (materials/data/measured/*/);
// empty where not.
std::filesystem::path measured_network(const MeasuredInplane& measured) {
  std::error_code ec;
  const auto net = std::filesystem::path(measured.file).parent_path() / "nbrdf_weights.txt";
  if (std::filesystem::is_regular_file(net, ec)) return net;
  return {};
}

// The colour table (paper's Table 1): the spectral ray-traced fabric at normal incidence, the
// summation's and the classic colour's spectra, the measurement's (the reference, in its own RGB
// space) and the paper's figure for its fabric.
std::vector<ColourEntry> colour_table(const TabulatedBsdfTable& computed, const VerifyInputs& in,
                                      const Rgb& measured_at_normal,
                                      MeasuredColourSpace measured_space) {
  std::vector<ColourEntry> out;
  if (computed.channels == kNumBands) {
    const FabricSpectra sp = normal_incidence_spectra(computed);
    out.push_back(colour_of_spectrum(
        "computed fabric, reflection", sp.reflectance,
        "directional reflectance at normal incidence (light and viewer on the same side)"));
    out.push_back(colour_of_spectrum(
        "computed fabric, transmission", sp.transmittance,
        "directional transmittance at normal incidence (light and viewer on opposite sides)"));
    if (in.summation && in.summation->channels == kNumBands) {
      const FabricSpectra ss = normal_incidence_spectra(*in.summation);
      out.push_back(colour_of_spectrum("paper's summation, reflection", ss.reflectance,
                                       "the summation transmits nothing"));
    }
    if (!in.classic_diffuse) {
      const double entering = classic_entering_fraction(in.classic_distribution, in.classic_ior);
      Spectrum diffuse = in.volume_albedo;
      for (double& v : diffuse) v /= entering;
      out.push_back(colour_of_spectrum("classic diffuse colour (fiber volume albedo / (1 - E))",
                                       diffuse, "before clipping to [0, 1]; " + in.classic_source));
    }
  }
  ColourEntry measured;
  measured.name = "measured (this table), normal incidence and view: the reference";
  measured.rgb = measured_at_normal;
  measured.hsv = rgb_to_hsv(measured.rgb);
  measured.comparable = absolute_comparable(measured_space);
  measured.colour_space = measured_space == MeasuredColourSpace::kSrgb     ? "linear sRGB"
                          : measured_space == MeasuredColourSpace::kCamera ? "camera RGB"
                                                                           : "RGB of unknown space";
  measured.note = "beta at normal incidence and view, in the measurement's own RGB space" +
                  (measured.comparable ? std::string()
                                       : "; " + not_comparable_note(measured_space) +
                                             " (hue only roughly comparable)");
  out.push_back(measured);
  ColourEntry paper;
  paper.name = "real fabric (paper, Table 1)";
  paper.hsv = {0.98, 0.99, 0.8};
  paper.rgb = {std::nan(""), std::nan(""), std::nan("")};
  paper.colour_space = "HSV only";
  paper.note = "Voloboy et al. 2010, Table 1: the paper's own red fabric, not this measurement";
  out.push_back(paper);
  return out;
}

}  // namespace

std::vector<VerifyTrace> verify_traces(const VerifySettings& s) {
  std::vector<VerifyTrace> out;
  for (const char* model : {"computed", "classic"})
    for (int k = 0; k < s.batches; ++k) out.push_back({model, k, trace_options(s, model, k)});
  return out;
}

ClassicFiber verify_classic_fiber(const VerifyInputs& in, const VerifySettings& s,
                                  const ProgressCallback& progress) {
  ClassicFiber c;
  // The fiber's volume albedo is a share of all the light hitting the fiber; the classic fiber's
  // reflectance is the albedo of the light that gets past its surface lobe, so it is the volume
  // albedo divided by what the lobe leaves (classic.h). Components outside [0, 1] are removed
  // (and reported).
  const double entering = classic_entering_fraction(in.classic_distribution, in.classic_ior);
  Rgb refl = bands_to_linear_srgb([&](int b) { return in.volume_albedo[b] / entering; });
  c.clip.clip(refl);
  for (double* v : {&refl.r, &refl.g, &refl.b})
    if (*v > 1) {
      c.clip.largest = std::max(c.clip.largest, *v - 1);
      ++c.clip.components;
      *v = 1;
    }
  if (in.classic_diffuse) {
    const Rgb d = *in.classic_diffuse;
    for (int k = 0; k < 3; ++k)
      if (!(d[k] >= 0 && d[k] <= 1))
        throw Error("", "classic_diffuse", "a reflectance lies in [0, 1]");
    refl = d;
    c.clip = GamutClip();
  }
  c.reflectance = refl;
  c.table = classic_fiber_table(refl, in.classic_distribution, in.classic_ior, s.resolution,
                                s.summation_samples, s.seed, s.threads, progress);
  return c;
}

VerifyReport run_verify(const WovenSample& sample, const VerifyInputs& in,
                        const MeasuredInplane& measured, const VerifySettings& s,
                        const ProgressCallback& progress, const VerifyTraced* traced) {
  const NormalPoint normal = check_run(in, measured, s);
  VerifyReport rep;
  rep.settings = s;
  rep.measured = measured;
  rep.seconds = in.seconds;
  rep.fiber_name = in.fiber_name;
  rep.colour_match = in.colour_match;
  rep.colour_calibrated = in.colour_calibrated;
  rep.sample_name = in.sample_name;
  const auto t_all = std::chrono::steady_clock::now();

  // Computed: the fiber-level ray trace of the fiber table.
  auto t0 = std::chrono::steady_clock::now();
  TracedCurves computed = trace_curves(sample, in.fiber, measured, s, "computed", progress, traced);
  if (computed.cancelled) {
    rep.cancelled = true;
    return rep;
  }
  rep.seconds["raytrace_computed"] = seconds_since(t0);
  add_computed_raytrace(rep, computed, in, sample);
  if (in.summation) rep.models.push_back(summation_curves(*in.summation, measured, s.azimuths));

  // Classic: Lambert + Cook-Torrance with the fiber's volume albedo as its diffuse colour.
  t0 = std::chrono::steady_clock::now();
  const ClassicFiber classic = verify_classic_fiber(in, s, progress);
  rep.classic_clip = classic.clip;
  rep.classic_reflectance = classic.reflectance;
  rep.classic_source = in.classic_source;
  TracedCurves cl = trace_curves(sample, classic.table, measured, s, "classic", progress, traced);
  if (cl.cancelled) {
    rep.cancelled = true;
    return rep;
  }
  rep.seconds["raytrace_classic"] = seconds_since(t0);
  rep.models.push_back(model_curves(verify_model(VerifyModel::kClassic).key,
                                    verify_model(VerifyModel::kClassic).label, cl.beta, cl.err,
                                    cl.batches));
  rep.classic_fabric = std::move(cl.mean);
  rep.classic_fiber = classic.table;
  rep.measured_nbrdf = measured_network(measured);

  for (auto& m : rep.models) score(m, measured, *normal.curve, normal.view);
  rep.colours =
      colour_table(computed.mean, in, normal.curve->beta[normal.view], measured.colour_space);
  rep.seconds["verify_library"] = seconds_since(t_all);
  return rep;
}

}  // namespace weft
