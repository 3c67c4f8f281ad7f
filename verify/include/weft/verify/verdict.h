#pragma once
// The verdict of a verification (docs/verify.md "Verdict"): for each figure, which of two models
// is closer to the measurement, and whether the difference exceeds its uncertainty (the seed's,
// from the ray trace's batches, and the measurement's own, from its fits).
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "weft/verify/figures.h"

namespace weft {

// How many seed standard errors a difference must exceed, against every fit of the measurement.
inline constexpr double kVerdictSeedErrors = 2;

// The smallest spread between fits (figures.h measured_fit_spread) over the bundled MERL
// measurements (materials/data/measured/merl-*/inplane.csv, three fits each), per figure in
// kFigureKeys order: what a difference must exceed against a measurement with one fit, whose own
// spread is unknown. Measured, and recomputed by a test, with
//   build/tests/weft_tests_verify --gtest_filter='VerifyVerdict.BundledFitSpread*'
inline constexpr std::array<double, 3> kMinBundledFitSpread = {0.071, 0.137, 0.112};

// Above this shape figure (RMS log) a model does not describe the measurement: where every
// model is above it, no verdict names a closer model.
inline constexpr double kNoModelShapeRmsLog = 1.0;

// What the verdict on a figure knows beyond the two models' figures.
struct VerdictContext {
  // measured_fit_spread of this figure; NaN where the measurement has one fit.
  double measured_spread = std::numeric_limits<double>::quiet_NaN();
  // Every model's shape figure is above kNoModelShapeRmsLog (no_model_describes).
  bool no_model_describes = false;
};

// Models a and b compared on one figure. difference = a - b (below 0: a is closer). Resolved when
// the difference has one sign against every fit of the measurement and for every batch (each
// batch's figures against each fit), exceeds kVerdictSeedErrors seed standard errors against
// every fit, and exceeds the measurement's own spread between its fits against every fit (with
// one fit: kMinBundledFitSpread). Otherwise a tie; no closer model where no model describes the
// measurement.
struct Verdict {
  std::string figure;               // kFigureKeys
  std::string a, b;                 // model keys
  double a_value = 0, b_value = 0;  // against the reference fit
  double difference = 0;            // against the reference fit
  double difference_seed_se = 0;    // its standard error over the batches (paired), reference
  std::vector<double> difference_per_fit;
  bool same_sign_fits = false, same_sign_batches = false, exceeds_seed = false;
  // The measurement's spread (NaN: one fit, spread unknown) and what the difference had to
  // exceed: that spread, or kMinBundledFitSpread with one fit.
  double measured_spread = std::numeric_limits<double>::quiet_NaN();
  double spread_required = 0;
  bool exceeds_spread = false;
  bool resolved = false;
  bool tie = false;  // defined, not resolved, and some model describes the measurement
  bool no_model_describes = false;
  // False for a figure that includes the colour's level against a measurement not in linear sRGB
  // (measured.h absolute_comparable): shown, labelled, and no verdict on it is meant.
  bool comparable = true;
  std::string closer;  // the closer model's key when resolved, else empty
  std::string text;    // in words, one sentence
};

// 'a_name', 'b_name': the models' names in the text.
Verdict compare_figure(FigureKind figure, const std::string& a_key, const std::string& a_name,
                       const FigureSamples& a, const std::string& b_key, const std::string& b_name,
                       const FigureSamples& b, const VerdictContext& context);

// Whether no model describes the measurement: every shape figure given is above
// kNoModelShapeRmsLog (false for none given).
bool no_model_describes(const std::vector<double>& shape_figures);

// A figure's name in words ("Shape", "Paper's one-point normalization", "Absolute"), and what it
// is, as the page and the summary label it.
std::string figure_name(FigureKind figure);
std::string figure_label(FigureKind figure);

}  // namespace weft
