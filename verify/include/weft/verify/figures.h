#pragma once
// The headline figures of a model's in-plane curves against the measurement (docs/verify.md
// "Metrics"): the shape (one gain per channel fitted in log space, the same freedom for every
// model), the paper's one-point normalization and the absolute figure; each of the mean curves
// and of every ray-trace batch, against every fit of the measurement (their uncertainty).
#include <array>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/verify/measured.h"

namespace weft {

// Views farther than this from the normal are left out of the shape figure and reported apart:
// there the measurement's own fits disagree most.
inline constexpr double kShapeMaxViewDeg = 80;

// The shape figure of a model against a measured fit: per channel c one gain g_c, with
// ln g_c = mean of ln(measured / model) over the points used (both positive, |view| <=
// kShapeMaxViewDeg): the least-squares gain in log space. Then the RMS of ln(g_c model /
// measured) over those points. The views beyond are scored apart with the same gains (their
// own would fit the level of a few grazing points and hide how the curve bends there).
struct ShapeFigure {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  Rgb gain{kNaN};
  double rms_log = kNaN;  // all channels and incidences: the headline
  std::array<double, 3> rms_log_channel{kNaN, kNaN, kNaN};
  std::vector<double> rms_log_incidence;  // [incidence], channels together
  double rms_log_grazing = kNaN;          // views beyond kShapeMaxViewDeg, the same gains
  size_t points = 0, grazing_points = 0;
  size_t excluded = 0;  // points where the model or the measurement is not positive
};
// 'model' and 'measured' at every (incidence, view) of 'geometry'.
ShapeFigure shape_figure(const InplaneCurves& model, const InplaneCurves& measured,
                         const MeasuredInplane& geometry);

// Where the measurement has normal incidence and normal view (the paper's normalization).
struct NormalIndex {
  size_t incidence = 0, view = 0;
};
// The measurement's normal point; none where it has no row at theta_i = 0, view = 0.
std::optional<NormalIndex> normal_index(const MeasuredInplane& measured);

// Log figures need both sides positive. The models' linear sRGB is not clamped, so a saturated
// colour outside the gamut has negative components, and a measurement may hold a dark point at
// 0. Before any figure each side's channel is floored at kLogFloorFraction of that channel's own
// maximum over its curves (scale-free, so the same for every model, gain and colour space); the
// points floored are counted and reported. A channel with no positive value takes the brightest
// channel's maximum; curves with no light at all have no floor, and their points stay excluded.
inline constexpr double kLogFloorFraction = 1e-3;
struct LogFloored {
  InplaneCurves curves;
  size_t floored = 0;  // components raised to their channel's floor
};
LogFloored floor_for_log(const InplaneCurves& curves);

// RMS of ln(model / measured) over every point where both are positive: as computed (absolute),
// and with the model scaled per channel to equal the measurement at the normal point (the
// paper's); NaN where the model is not positive there (no factor exists).
double absolute_figure(const InplaneCurves& model, const InplaneCurves& measured);
double paper_figure(const InplaneCurves& model, const InplaneCurves& measured, NormalIndex normal);

// The three figures, in this order everywhere (metrics.json's keys).
enum FigureKind : int { kShapeFigure = 0, kPaperFigure = 1, kAbsoluteFigure = 2 };
inline constexpr std::array<const char*, 3> kFigureKeys = {"shape", "paper_normalized", "absolute"};

// One figure's values: of the mean curves and of each batch, against each fit of the measurement
// (fit 0 the reference).
struct FigureSamples {
  std::vector<double> mean;                // [fit]
  std::vector<std::vector<double>> batch;  // [fit][batch]; empty for a deterministic model
  double value() const { return mean.at(0); }
  // Against the reference: the standard deviation of the batches' figures (the seed spread of
  // one batch) and seed_sd / sqrt(batches), the standard error of the mean curves' figure (what
  // the report shows after "+-"); 0 for a deterministic model.
  double seed_sd() const;
  double seed_se() const;
  double fit_min() const;  // the mean curves' figure over the fits
  double fit_max() const;
};

struct ModelFigures {
  std::vector<std::string> fits;  // the measurement's fits, reference first
  std::array<FigureSamples, 3> figure;
  ShapeFigure shape;              // the mean curves against the reference, in detail
  size_t log_floored_points = 0;  // of the mean curves (floor_for_log)
};
// Every figure is of the curves floored by floor_for_log (the model's and each fit's).
// 'batches': each batch's curves ([batch][incidence][view]); empty for a deterministic model.
ModelFigures model_figures(const InplaneCurves& mean, const std::vector<InplaneCurves>& batches,
                           const MeasuredInplane& measured, NormalIndex normal);

// The measurement's own spread on each figure (kFigureKeys order): the largest figure between two
// of its fits, one taken as the model and the other as the reference (floored as above; the
// figures are symmetric in the pair). An RMS of log ratios obeys the triangle inequality, so this
// bounds how far a model's shape or absolute figure can move when another fit is the reference: a
// difference between two models below it can turn with the choice of fit. NaN with one fit.
std::array<double, 3> measured_fit_spread(const MeasuredInplane& measured, NormalIndex normal);

// The sample standard deviation (n - 1) of 'values'; 0 for fewer than two.
double sample_sd(const std::vector<double>& values);

}  // namespace weft
