#pragma once
// The run of a verification (docs/verify.md): for every incidence of the measured in-plane table,
// beta = pi f in the plane of incidence of
//   * the computed fabric: fabric tables of the woven sample made from the fiber table, by the
//     fiber-level ray trace (fabric/fabric_raytrace.h) and by the paper's summation
//     (fabric/fabric_summation.h, made by the caller);
//   * the classic baseline: a Lambert + Cook-Torrance fiber (materials/classic_fiber.h) whose
//     diffuse colour is the fiber's volume albedo, tabulated as a fiber table and ray-traced on the
//     same sample, so the two differ only in the fiber's BSDF;
//   * the measurement;
// and the metrics that compare them, and the fabric's colour (paper's Table 1).
#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/spectrum.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/microfacet.h"
#include "weft/scenes/weave.h"
#include "weft/verify/colour.h"
#include "weft/verify/figures.h"
#include "weft/verify/fit.h"
#include "weft/verify/inplane.h"
#include "weft/verify/measured.h"
#include "weft/verify/metrics.h"
#include "weft/verify/render.h"
#include "weft/verify/settings.h"

namespace weft {

// What the caller brings: the fiber physics' results (the fiber bake) and the summation table.
struct VerifyInputs {
  TabulatedBsdfTable fiber;  // fiber table (spectral for the colour table, or RGB)
  // The fiber's volume albedo per band (albedo minus the surface part): the classic model's
  // diffuse colour.
  Spectrum volume_albedo{};
  MicrofacetDistribution classic_distribution;  // the fiber's surface roughness
  double classic_ior = 1.5;
  std::optional<TabulatedBsdfTable> summation;  // the paper's summation table (any channels)
  // A fitted classic colour (linear sRGB reflectance in [0, 1]) in place of the volume albedo.
  std::optional<Rgb> classic_diffuse;
  std::string fiber_name, sample_name;
  // Where the classic model's colour, roughness and index came from (for the report).
  std::string classic_source =
      "the fiber spec: volume albedo of the bake over the share past the classic lobe, the "
      "spec's roughness "
      "and index at 550 nm";
  std::map<std::string, double> seconds;  // timings of the caller's steps (fiber bake, ...)
  // With a colour (VerifyRequest::colour): the match's summary (fiber/colour_match.h); whether it
  // calibrates the computed model to the measurement's own reading (--colour-from measured).
  nlohmann::json colour_match;
  bool colour_calibrated = false;
};

// One model's curves: per measured incidence, beta at every measured view, and its standard
// error (zero where the model is deterministic).
struct ModelCurves {
  std::string key, label;
  InplaneCurves beta, beta_err;
  // Each ray-trace batch's curves (beta is their mean); empty where the model is deterministic.
  std::vector<InplaneCurves> batch_beta;
  // The headline figures (shape, paper's, absolute) with their spread over the batches and over
  // the measurement's fits.
  ModelFigures figures;
  Rgb normalization{1.0};  // paper's, per channel
  // [incidence] then overall ("all" last): absolute and normalized metrics, channels together.
  std::vector<CurveMetrics> absolute, normalized;
  // [incidence][channel]: each curve (one incidence, one channel) on its own.
  std::vector<std::array<CurveMetrics, 3>> absolute_channel, normalized_channel;
  CurveMetrics absolute_overall, normalized_overall;
};

// A model's fabric table as weft view's page (exchange/preview_html.h), written beside index.html.
struct VerifyPreview {
  std::string model, file, label;  // "computed", "preview-computed.html", what the table is
};

struct VerifyReport {
  VerifySettings settings;
  MeasuredInplane measured;
  // "computed_raytrace", "computed_summation"?, "classic"; with --fit also
  // "computed_raytrace_fitted" and "classic_fitted" (the fitted parameters at the run's quality).
  std::vector<ModelCurves> models;
  std::vector<ColourEntry> colours;
  Rgb classic_reflectance;     // the classic model's diffuse colour (linear sRGB, clipped to [0,1])
  GamutClip classic_clip;      // what making it a reflectance removed
  std::string classic_source;  // VerifyInputs::classic_source
  std::map<std::string, double> seconds;
  std::string fiber_name, sample_name;
  nlohmann::json colour_match;  // VerifyInputs::colour_match
  bool colour_calibrated = false;
  size_t fabric_table_gamut_clipped = 0;  // components of the computed table set to 0: none now
  // Components of the computed table's linear sRGB below 0 (a saturated colour), kept as they are.
  OutOfGamut fabric_table_out_of_gamut;
  double raytrace_relative_noise = 0;  // of the combined computed table (fabric_raytrace.h)
  std::vector<FitResult> fits;         // with --fit: "computed", "classic"
  // What the renders show: the ray-traced fabric tables of the computed and the classic fiber
  // (the mean of the batches) and the measured BRDF's network, where the measurement has one
  // (nbrdf_weights.txt beside the table; empty: none).
  std::optional<TabulatedBsdfTable> computed_fabric, classic_fabric;
  std::filesystem::path measured_nbrdf;
  // What the fiber-level renders show: the sample (when at fiber detail) and the fiber tables of
  // the computed and the classic model (VerifyInputs::fiber, ClassicFiber::table).
  std::shared_ptr<const WovenSample> sample;
  std::optional<TabulatedBsdfTable> computed_fiber, classic_fiber;
  std::vector<VerifyRender> renders;  // made by write_verify_report
  // Made by write_verify_report (write_verify_previews); why there are none, when there are none.
  std::vector<VerifyPreview> previews;
  std::string previews_skipped;
  bool cancelled = false;
};

// Whether the absolute figures are judged: the measurement is in the models' space (linear sRGB),
// or the run was calibrated to the measurement's own d/8 reading (--colour-from measured), so that
// the colour level came from the measurement itself and the figure judges the rest.
inline bool absolute_judged(const VerifyReport& r) {
  return r.colour_calibrated || absolute_comparable(r.measured.colour_space);
}

// The ray traces of a verification, most of its time: per model, settings.batches independent
// raytrace_fabric_table runs of every incident bin ("computed": of the fiber table; "classic": of
// verify_classic_fiber's table). In run_verify's order: the computed batches, then the classic.
// A front end may run them in pieces over processes (first_bin, bin_count: the rows, energy books
// and noise of the whole run, bit for bit, fabric_raytrace.h) and hand the results in.
struct VerifyTrace {
  std::string model;  // "computed" or "classic"
  int batch = 0;
  FabricRaytraceOptions options;  // of the whole table
};
std::vector<VerifyTrace> verify_traces(const VerifySettings& settings);

// The classic model's fiber: its diffuse colour (the fiber's volume albedo as linear sRGB, made a
// reflectance in [0, 1] with what that removed in 'clip'; or inputs.classic_diffuse) and its
// fiber table, which the classic ray traces use.
struct ClassicFiber {
  Rgb reflectance;
  GamutClip clip;
  TabulatedBsdfTable table;
};
ClassicFiber verify_classic_fiber(const VerifyInputs& inputs, const VerifySettings& settings,
                                  const ProgressCallback& progress = no_progress());

// Ray traces done elsewhere, by (model, batch): run_verify takes them instead of tracing.
using VerifyTraced = std::map<std::pair<std::string, int>, FabricRaytraceResult>;

VerifyReport run_verify(const WovenSample& sample, const VerifyInputs& inputs,
                        const MeasuredInplane& measured, const VerifySettings& settings,
                        const ProgressCallback& progress = no_progress(),
                        const VerifyTraced* traced = nullptr);

}  // namespace weft
