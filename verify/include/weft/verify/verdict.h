#pragma once
// The verdict of a verification (docs/verify.md "Verdict"): for each figure, which of two models
// is closer to the measurement, and whether the difference exceeds its uncertainty (the seed's,
// from the ray trace's batches, and the measurement's own, from its fits).
#include <string>
#include <vector>

#include "weft/verify/figures.h"

namespace weft {

// How many seed standard errors a difference must exceed, against every fit of the measurement.
inline constexpr double kVerdictSeedErrors = 2;

// Models a and b compared on one figure. difference = a - b (below 0: a is closer). Resolved when
// the difference has one sign against every fit of the measurement and for every batch (each
// batch's figures against each fit), and exceeds kVerdictSeedErrors seed standard errors against
// every fit.
struct Verdict {
  std::string figure;               // kFigureKeys
  std::string a, b;                 // model keys
  double a_value = 0, b_value = 0;  // against the reference fit
  double difference = 0;            // against the reference fit
  double difference_seed_se = 0;    // its standard error over the batches (paired), reference
  std::vector<double> difference_per_fit;
  bool same_sign_fits = false, same_sign_batches = false, exceeds_seed = false;
  bool resolved = false;
  // False for a figure that includes the colour's level against a measurement not in linear sRGB
  // (measured.h absolute_comparable): shown, labelled, and no verdict on it is meant.
  bool comparable = true;
  std::string closer;  // the closer model's key when resolved, else empty
  std::string text;    // in words, one sentence
};

// 'a_name', 'b_name': the models' names in the text.
Verdict compare_figure(FigureKind figure, const std::string& a_key, const std::string& a_name,
                       const FigureSamples& a, const std::string& b_key, const std::string& b_name,
                       const FigureSamples& b);

// A figure's name in words ("Shape", "Paper's one-point normalization", "Absolute"), and what it
// is, as the page and the summary label it.
std::string figure_name(FigureKind figure);
std::string figure_label(FigureKind figure);

}  // namespace weft
