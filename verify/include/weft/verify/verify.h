#pragma once
// weft verify (docs/verify.md): the paper's verification (Voloboy et al. 2010, section 4) in one
// call. For every incidence angle of a measured in-plane table, the radiance coefficient
// beta = pi f in the plane of incidence of
//   * the computed fabric: fabric tables of the woven sample made from the fiber table, by the
//     fiber-level ray trace (fabric/fabric_raytrace.h) and by the paper's summation (made by
//     the caller: the summation lives in the fiber physics, which this library does not link);
//   * the classic baseline: a Lambert + Cook-Torrance fiber (materials/classic_fiber.h) whose
//     diffuse colour is the fiber's volume albedo, tabulated as a fiber table and ray-traced on the
//     same sample, so the two differ only in the fiber's BSDF;
//   * the measurement;
// and the metrics that compare them (absolute and with the paper's normalization), the fabric's
// colour in reflection and transmission (paper's Table 1), and the report files.
//
// Why the tables and not the gonioreflectometer sweep: a fabric table is the cloth's BSDF, the
// quantity a gonioreflectometer on an infinite sample measures, so beta at any (incidence, view)
// is pi times the table's value; one table serves every incidence, where the sweep renders one
// image per view and incidence (9 x 35 renders for the bundled measurement) and adds the edges of
// a finite patch. The table's resolution limits the angular detail (a bin spans about
// 180 / (2 R) degrees), which the quality levels trade against time.
//
// In-plane directions (cloth frame, z = normal): light at zenith theta_i and azimuth phi,
// w_i = (sin theta_i cos phi, sin theta_i sin phi, cos theta_i); a view zenith v > 0 lies on the
// mirror side (the paper's Fig. 7), w_o = (-sin v cos phi, -sin v sin phi, cos v). The measured
// tables are of isotropic fits, so the computed values are averaged over 'azimuths' planes
// phi = 360 k / azimuths.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/math.h"
#include "weft/core/progress.h"
#include "weft/core/spectrum.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/integrators/image.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/microfacet.h"
#include "weft/scenes/description.h"
#include "weft/scenes/weave.h"

namespace weft {

// ---- The measurement -------------------------------------------------------------------------

// One incidence of a measured in-plane table; views in the paper's sign (> 0 on the mirror side).
struct MeasuredCurve {
  double theta_i_deg = 0;
  std::vector<double> view_deg;
  std::vector<Rgb> beta;
};

struct MeasuredInplane {
  std::string file;
  std::vector<MeasuredCurve> curves;  // by increasing theta_i
};

// Reads a table in the format of materials/data/measured/*/inplane.csv: optional comment lines
// starting with '#' or '"#', a header naming at least theta_i_deg, theta_o_deg, nbrdf_beta_R,
// nbrdf_beta_G, nbrdf_beta_B, and one row per (theta_i, theta_o) with theta_o < 0 on the mirror
// side (that table's convention; flipped here). weft::Error naming the file and the column (or
// line) on a missing file or column, a non-number, a negative or non-finite beta, an angle out of
// range, or a duplicate row.
MeasuredInplane read_measured_inplane(const std::filesystem::path& path);

// The bundled MERL red fabric (materials/data/measured/merl-red-fabric/inplane.csv), found in the
// source tree or the installed tree; weft::Error listing the places tried.
std::filesystem::path bundled_measured_inplane();

// ---- Evaluating a table in the plane of incidence ---------------------------------------------

// beta = pi f of an RGB table (3 channels), averaged over 'azimuths' planes of incidence, for
// each view of 'views_deg' (paper's sign).
std::vector<Rgb> inplane_beta(const TabulatedBsdfTable& rgb_table, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths);

// A spectral table (33 bands) as linear sRGB under D65 (core/spectrum.h bands_to_linear_srgb);
// negative components (out of gamut) are set to 0 and counted in 'clip'. A 3-channel table is
// returned as it is.
TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& table, GamutClip* clip = nullptr);

// ---- Metrics ---------------------------------------------------------------------------------

// model vs measurement over points where both are positive: RMS of ln(model / measured) and of
// (model - measured) / measured. Points where either is <= 0 are not in the RMS and are counted
// in 'excluded' (a log ratio is undefined there).
struct CurveMetrics {
  double rms_log = 0, rms_rel = 0;
  size_t points = 0, excluded = 0;
};

// Accumulates squared errors of points; 'result' gives the RMS over what was added.
struct MetricsAccumulator {
  double sum_log2 = 0, sum_rel2 = 0;
  size_t points = 0, excluded = 0;
  void add(double model, double measured);
  void add(const MetricsAccumulator& other);
  CurveMetrics result() const;
};

// The paper's normalization, per channel: the factor that makes the model's beta at normal
// incidence and normal view equal the measured one. weft::Error when the model's value is not
// positive there (no factor exists).
Rgb paper_normalization(const Rgb& model_at_normal, const Rgb& measured_at_normal,
                        const std::string& model_name);

// ---- Colour (paper's Table 1) ----------------------------------------------------------------

struct ColourEntry {
  std::string name;
  std::optional<Spectrum> spectrum;  // absent for entries given as RGB or HSV
  Rgb linear_srgb;                   // D65, unclipped (negative = out of gamut)
  Hsv hsv;                           // of the linear sRGB with negative components set to 0
  std::string note;
};

// The colour of a reflectance or transmittance spectrum under D65 through CIE 1931.
ColourEntry colour_of_spectrum(const std::string& name, const Spectrum& spectrum,
                               const std::string& note);

// Reflectance and transmittance spectra of a spectral fabric table (33 bands) at normal
// incidence (the directional albedo of the wi bin containing the normal, materials/bsdf_table.h).
struct FabricSpectra {
  Spectrum reflectance{}, transmittance{};
};
FabricSpectra normal_incidence_spectra(const TabulatedBsdfTable& spectral_table);

// ---- The whole verification ------------------------------------------------------------------

enum class VerifyQuality { kDraft, kDefault, kPublication };
VerifyQuality parse_verify_quality(const std::string& name);  // weft::Error naming "--quality"
std::string quality_name(VerifyQuality q);

// What a quality level sets. One place for the figures (docs/verify.md gives their times).
struct VerifySettings {
  VerifyQuality quality = VerifyQuality::kDefault;
  int resolution = 8;                   // of the fiber and fabric tables
  uint64_t fiber_photons_per_band = 0;  // the fiber bake
  uint64_t particles_per_bin = 0;       // ray trace, all batches together
  int batches = 4;                      // independent ray traces (the error bars)
  int summation_samples = 8;            // direction pairs per cell pair (summation, classic)
  int azimuths = 24;                    // planes of incidence averaged
  int render_size = 96;                 // the renders of the sample (pixels per side)
  int render_spp = 4;                   // their samples per pixel
  int weave_render_size = 160;          // the fiber-level renders (pixels on the longer side)
  int weave_render_spp = 16;            // their samples per pixel
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores; results do not depend on it
};
VerifySettings verify_settings(VerifyQuality quality);

// What the caller brings: the fiber physics' results (this library does not link them).
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
      "the fiber spec: volume albedo of the bake, the spec's roughness "
      "and index at 550 nm";
  std::map<std::string, double> seconds;  // timings of the caller's steps (fiber bake, ...)
};

// One model's curves: per measured incidence, beta at every measured view, and its standard
// error (zero where the model is deterministic).
struct ModelCurves {
  std::string key, label;
  std::vector<std::vector<Rgb>> beta, beta_err;  // [incidence][view]
  Rgb normalization{1.0};                        // paper's, per channel
  // [incidence] then overall ("all" last): absolute and normalized metrics, channels together.
  std::vector<CurveMetrics> absolute, normalized;
  // [incidence][channel]: each curve (one incidence, one channel) on its own.
  std::vector<std::array<CurveMetrics, 3>> absolute_channel, normalized_channel;
  CurveMetrics absolute_overall, normalized_overall;
};

// ---- Fitting (at most four physical parameters, the same budget for both models) -------------

// One fitted parameter: its box [lo, hi] and start; 'log_scale' searches ln(x) (for scales that
// span decades). The optimizer works in the unit cube u in [0, 1] of each box.
struct FitParameter {
  std::string name, unit;
  double lo = 0, hi = 1, start = 0.5;
  bool log_scale = false;
};

// A parameter's value as its coordinate in the optimizer's unit cube (ln x where log_scale).
double fit_unit(const FitParameter& p, double x);

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

struct FitOptions {
  FitMethod method = FitMethod::kLevenbergMarquardt;
  int max_evaluations = 100;  // of the objective during the search (the uncertainty adds 2 p + 1)
  // Converged: Nelder-Mead when the simplex's objective values span less than this (and its edges
  // are below 1e-3 of each box); Levenberg-Marquardt when a step lowers the objective by less than
  // this and its model predicted no more, or when no step longer than 1e-3 of a box lowers it.
  double tolerance = 1e-4;
  double initial_step = 0.15;  // Nelder-Mead's simplex edge, as a fraction of each box
  // Finite differences, fraction of each box: Levenberg-Marquardt's one-sided Jacobians during
  // the search, and the central differences of the uncertainty at the optimum.
  double jacobian_step = 0.02;
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
};

struct FitResult {
  std::string model;        // "computed" or "classic"
  std::string inner_model;  // what the objective evaluated (docs/verify.md)
  std::vector<FitParameterResult> parameters;
  double objective_start = 0, objective = 0;   // rms_log, absolute, of the inner model
  CurveMetrics start_metrics, fitted_metrics;  // the inner model's absolute metrics
  int evaluations = 0;
  bool converged = false;  // the tolerance was met before max_evaluations
  std::string method;      // fit_method_name of the search
  double seconds = 0;
  std::string uncertainty =
      "Gauss-Newton: covariance s^2 (J^T J)^-1 of the log residuals at the optimum, J by central "
      "differences, s^2 = SSR / (n - p); treats the residuals as independent";
};

// The residuals the fit minimizes: ln(model / measured) at every view, incidence and channel
// where the measurement is positive (the points of rms_log); a model value <= 0 counts as
// ln(1e-6), a penalty, so the vector's length does not depend on the parameters.
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
//   kRaytrace: the run's own pipeline (RGB fiber bake, then the fiber-level ray trace) with few
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
  int summation_samples = 4;          // the summation's and the classic fiber table's
  uint64_t seed = 1;
  int azimuths = 24;
  int threads = 0;
};
FitInnerSettings fit_inner_settings(const VerifySettings& settings);

// ---- A baked fiber table in place of a spec (weft verify --fiber TABLE) ------------------------

// The classic fiber's diffuse colour from a fiber table alone, per channel of the table: the
// table's total albedo minus that of the classic fiber's own Cook-Torrance lobe (diffuse colour 0,
// tabulated by classic_fiber_table at R = 16, 4 samples per cell pair), so that the classic fiber
// sends out as much light in all as the table's fiber. For a table baked from a spec this stands
// for the volume albedo exit_fraction - surface_fraction: the lobe's albedo and the bake's surface
// fraction are those of the same rough surface (docs/verify.md gives the figures). Channels may
// come out negative (a table darker than its surface alone); the caller decides.
std::vector<double> classic_diffuse_from_fiber_table(const TabulatedBsdfTable& fiber,
                                                     const MicrofacetDistribution& d, double ior,
                                                     uint64_t seed, int threads);

// The fiber surface's roughness that a fiber table's header states ("roughness": "beckmann alpha
// 0.350000", as weft bake fiber writes it); nullopt when the header has none; weft::Error naming
// 'file' and "roughness" when it is malformed or out of (0, 1].
std::optional<MicrofacetDistribution> fiber_table_roughness(const TabulatedBsdfTable& table,
                                                            const std::string& file);

// beta [incidence][view] of an RGB or spectral table at the measurement's views.
std::vector<std::vector<Rgb>> table_curves(const TabulatedBsdfTable& table,
                                           const MeasuredInplane& measured, int azimuths);

// ---- Renders of the sample (paper's Figs. 8-9) -----------------------------------------------

// One render of a flat patch of cloth (docs/verify.md "Renders"): the model's fabric table (or the
// measured BRDF) on a 1 m square, a parallel light of irradiance pi at normal incidence, from the
// viewer's side ("reflection") or from behind ("transmission"), an orthographic camera at 30 deg
// from the normal. A flat patch under a parallel light has one radiance, L = f E cos theta_i =
// pi f = beta for this (view, light): the image is that colour, as the renderer shades it.
struct VerifyRender {
  std::string stem;           // file name without extension, e.g. "render-reflection-computed"
  std::string kind;           // "patch" (the fabric table) or "weave" (the fibers, below)
  std::string model;          // "computed", "classic", "measured"
  std::string configuration;  // "reflection", "transmission"
  std::string caption;
  Image image;         // linear sRGB radiance
  Rgb patch_radiance;  // patch: mean over the central half of the film (wholly inside the patch)
  Rgb mean;            // mean over the whole image
};

// The geometry of every render (one place for the numbers the captions and tests quote).
inline constexpr double kVerifyRenderViewZenithDeg = 30;
inline constexpr double kVerifyRenderIrradiance = kPi;  // L = beta
// The PNGs: linear radiance times 1 (a white Lambertian patch would be 1, white), clipped to
// [0, 1], sRGB transfer curve (image.h write_png_preview); no other tone mapping. EXR: linear.
inline constexpr double kVerifyRenderExposure = 1;
inline constexpr const char* kVerifyRenderSetup =
    "A flat 1 m square of cloth with the model's fabric table (the measured BRDF's neural fit for "
    "the measurement), lit by a parallel light of irradiance pi at normal incidence, from the "
    "viewer's side (reflection) or from behind (transmission), seen by an orthographic camera 30 "
    "deg from the normal; the path tracer of weft render. Under a parallel light a flat patch has "
    "one radiance, beta = pi f for that view and light, so each image is one colour. PNG: linear "
    "radiance times 1 (a white Lambertian patch would be white), clipped to [0, 1], sRGB transfer "
    "curve, no other tone mapping; EXR: linear sRGB radiance.";

// The renders' scene description (in memory): the patch named "cloth" bound to 'material'.
nlohmann::json verify_render_scene(const nlohmann::json& material, bool transmission,
                                   const VerifySettings& settings);

// The fiber-level renders (docs/verify.md "Renders"): the woven sample's fibers, as Embree round
// curves, every fiber with the model's fiber table, shaded by the renderer as any scene's fibers
// (RenderScene, path_tracer.h: the whole-fiber table, rays leaving a fiber ignore it, every other
// fiber occludes and inter-reflects). Lit as the patch (a parallel light of irradiance pi at
// normal incidence, from the viewer's side or from behind) and seen from the same direction (30
// deg from the normal, azimuth 180 deg from the warp) by an orthographic camera whose film is
// whole repeats of the cloth: repeats_z along the film's width (the weft direction) and repeats_x
// along its height (the warp, foreshortened by cos 30 deg), chosen so that each side comes near
// kVerifyWeaveFrameMm. Over whole repeats the film's mean is the cloth's mean radiance for that
// view and light, which the fabric table (the patch render) estimates too. The sample is tiled
// (weave.h tiled_woven_description) so that the cloth reaches a repeat past the film on every side.
inline constexpr double kVerifyWeaveFrameMm = 1.4;
struct VerifyWeaveFrame {
  int repeats_x = 1, repeats_z = 1;  // whole repeats on the film's height and width
  double half_width_m = 0, half_height_m = 0;
  int width = 1, height = 1;       // pixels: the longer side 'size', square to within a pixel
  int copies_x = 1, copies_z = 1;  // tiled copies on each side of the sample's own
};
// weft::Error when the sample has no period or size < 1.
VerifyWeaveFrame verify_weave_frame(const WeaveSummary& sample, int size);
// The scene (in memory): the tiled fibers, materials "warp" and "weft" bound to 'material' (its
// relative paths resolve against 'base_dir'), the light, the camera and the render settings
// (weave_render_size, weave_render_spp, seed). weft::Error when the sample is not at fiber detail.
SceneDescription verify_weave_scene(const WovenSample& sample, const nlohmann::json& material,
                                    bool transmission, const VerifySettings& settings,
                                    const std::filesystem::path& base_dir);
inline constexpr const char* kVerifyWeaveRenderSetup =
    "The woven sample at fiber detail, tiled, every fiber an Embree round curve with the model's "
    "fiber table (shaded as weft render shades fibers: the whole-fiber table, no occlusion by the "
    "fiber a ray leaves, occlusion and inter-reflection by every other fiber; the table read by "
    "cell, as the fabric ray trace reads it, so the two are one transport), lit and seen as "
    "the patch above: a parallel light of irradiance pi at normal incidence, from the viewer's "
    "side (reflection) or from behind (transmission), an orthographic camera 30 deg from the "
    "normal whose film spans whole repeats, so the image's mean is the cloth's mean radiance for "
    "that view and light. Black: gaps between the yarns. Same tone mapping as above.";

// Renders what the report holds: computed and classic fabric tables in both configurations, the
// measured BRDF (report.measured_nbrdf) in reflection; and where the report holds the sample at
// fiber detail, the fibers with the computed and classic fiber tables in both configurations
// (verify_weave_scene; stems render-weave-CONFIGURATION-MODEL). The tables are written into
// 'folder' first (fabric-computed.exr, fabric-classic.exr, fiber-classic.exr in RGB;
// fiber-computed.exr as the model has it, spectral, and rendered as a spectral render), where the
// renderer reads them as any scene's fabric_table or fiber_table; the images are returned, not
// written.
struct VerifyReport;
std::vector<VerifyRender> render_verify_samples(const std::filesystem::path& folder,
                                                const VerifyReport& report);

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
  size_t fabric_table_gamut_clipped = 0;  // components of the computed table set to 0
  double raytrace_relative_noise = 0;     // of the combined computed table (fabric_raytrace.h)
  std::vector<FitResult> fits;            // with --fit: "computed", "classic"
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
  bool cancelled = false;
};

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

// The report's files, as text: the long-form curves CSV and metrics JSON (stable keys,
// docs/verify.md), and the offline HTML page embedding the given images (file name -> bytes).
std::string verify_inplane_csv(const VerifyReport& report);
std::string verify_metrics_json(const VerifyReport& report);
std::string verify_index_html(const VerifyReport& report,
                              const std::vector<std::pair<std::string, std::string>>& images);

// Writes DIR whole or not at all: the renders (render_verify_samples: fabric-*.exr, render-*.exr
// and .png), inplane.csv and metrics.json into a staging folder beside DIR, then draw(staging)
// (the plots: inplane-*.png and .svg files it writes there), then index.html embedding the plots
// and linking the renders by relative path, then the staging folder replaces DIR. DIR must not
// exist, be empty, or hold an earlier report (its metrics.json has "report": "weft verify");
// anything else is refused (weft::Error naming DIR) and left alone. The check write_verify_report
// makes first, for callers to make before the work.
void check_verify_output(const std::filesystem::path& dir);
void write_verify_report(const std::filesystem::path& dir, const VerifyReport& report,
                         const std::function<void(const std::filesystem::path& staging)>& draw);

}  // namespace weft
