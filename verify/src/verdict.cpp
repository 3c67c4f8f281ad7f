#include "weft/verify/verdict.h"

#include <cmath>

#include "common.h"
#include "weft/core/error.h"

namespace weft {
namespace {

// d[batch] = a - b against one fit, pairing batch k with batch k (a deterministic model's one
// value with every batch of the other); empty when neither has batches.
std::vector<double> batch_differences(const FigureSamples& a, const FigureSamples& b, size_t fit) {
  std::vector<double> d;
  const size_t na = a.batch.empty() ? 0 : a.batch[fit].size();
  const size_t nb = b.batch.empty() ? 0 : b.batch[fit].size();
  if (na && nb && na != nb)
    throw Error("", "batches", "two models with different numbers of batches");
  for (size_t k = 0; k < std::max(na, nb); ++k)
    d.push_back((na ? a.batch[fit][k] : a.mean[fit]) - (nb ? b.batch[fit][k] : b.mean[fit]));
  return d;
}

int sign(double x) {
  return x > 0 ? 1 : (x < 0 ? -1 : 0);
}

// "above the measurement's own spread 0.06 between its 3 fits", or with one fit what stood in.
std::string spread_words(const Verdict& v, const char* relation) {
  if (std::isfinite(v.measured_spread))
    return std::string(relation) + " the measurement's own spread " + fmt(v.measured_spread, 2) +
           " between its " + std::to_string(v.difference_per_fit.size()) + " fits";
  return "one fit: spread unknown; " + std::string(relation) + " " + fmt(v.spread_required, 2) +
         ", the smallest spread between fits on the bundled MERL measurements";
}

// Why a defined difference is a tie, the first reason that holds.
std::string tie_reason(const Verdict& v) {
  if (v.difference == 0) return "no difference";
  if (!v.same_sign_fits) return "the sign differs between the measurement's fits";
  if (!v.exceeds_spread) return spread_words(v, "within");
  if (!v.exceeds_seed) return "within " + fmt(kVerdictSeedErrors, 2) + " seed standard errors";
  return "the sign differs between batches";
}

std::string verdict_text(const Verdict& v, FigureKind figure, const std::string& a_name,
                         const std::string& b_name) {
  // The closer model's figure first when resolved; else in the pair's order.
  const bool b_first = v.resolved && v.closer == v.b;
  const std::string values = fmt(b_first ? v.b_value : v.a_value, 2) + " vs " +
                             fmt(b_first ? v.a_value : v.b_value, 2) + " RMS log";
  const std::string seed =
      fmt(std::abs(v.difference), 2) + " +- " + fmt(v.difference_seed_se, 1) + " seed";
  double lo = v.difference_per_fit.at(0), hi = lo;
  for (double d : v.difference_per_fit) lo = std::min(lo, d), hi = std::max(hi, d);
  const std::string fits = std::to_string(v.difference_per_fit.size()) +
                           (v.difference_per_fit.size() == 1 ? " fit" : " fits");
  if (v.resolved) {
    const bool a_closer = v.closer == v.a;
    return figure_name(figure) + ": " + (a_closer ? a_name : b_name) + " is closer than " +
           (a_closer ? b_name : a_name) + " (" + values + ", difference " + seed + ", " +
           spread_words(v, "above") + ", same sign against all " + fits +
           " of the measurement and every batch)";
  }
  const std::string pair = figure_name(figure) + ", " + a_name + " vs " + b_name;
  if (!std::isfinite(v.difference))
    return pair + ": no verdict (" + values + "; a figure is not defined)";
  if (v.no_model_describes)
    return pair + ": no model here describes the sample (every model's shape RMS log is above " +
           fmt(kNoModelShapeRmsLog, 2) + "), so none is named closer (" + values + ")";
  return pair + ": a tie (" + values + ", difference (first minus second) " + fmt(v.difference, 2) +
         " +- " + fmt(v.difference_seed_se, 1) + " seed, " + fmt(lo, 2) + ".." + fmt(hi, 2) +
         " against the " + fits + " of the measurement; " + tie_reason(v) + ")";
}

}  // namespace

std::string figure_name(FigureKind figure) {
  switch (figure) {
    case kShapeFigure:
      return "Shape";
    case kPaperFigure:
      return "Paper's one-point normalization";
    case kAbsoluteFigure:
      break;
  }
  return "Absolute";
}

std::string figure_label(FigureKind figure) {
  switch (figure) {
    case kShapeFigure:
      return "shape: one gain per channel fitted in log space, the same for every model, views "
             "within " +
             fmt(kShapeMaxViewDeg) + " deg of the normal (the headline)";
    case kPaperFigure:
      return "paper's one-point normalization (Voloboy et al. 2010): hinges on the "
             "normal-incidence, normal-view point";
    case kAbsoluteFigure:
      break;
  }
  return "absolute: includes colour level";
}

Verdict compare_figure(FigureKind figure, const std::string& a_key, const std::string& a_name,
                       const FigureSamples& a, const std::string& b_key, const std::string& b_name,
                       const FigureSamples& b, const VerdictContext& context) {
  Verdict v;
  v.figure = kFigureKeys[figure];
  v.a = a_key;
  v.b = b_key;
  v.a_value = a.value();
  v.b_value = b.value();
  v.difference = v.a_value - v.b_value;
  const int s = sign(v.difference);
  v.measured_spread = context.measured_spread;
  v.spread_required = std::isfinite(context.measured_spread) ? context.measured_spread
                                                             : kMinBundledFitSpread[figure];
  v.same_sign_fits = v.same_sign_batches = v.exceeds_seed = v.exceeds_spread =
      std::isfinite(v.difference) && s != 0;
  for (size_t f = 0; f < a.mean.size() && f < b.mean.size(); ++f) {
    const double d = a.mean[f] - b.mean[f];
    v.difference_per_fit.push_back(d);
    if (!(sign(d) == s)) v.same_sign_fits = false;
    const std::vector<double> db = batch_differences(a, b, f);
    const double se = db.empty() ? 0.0 : sample_sd(db) / std::sqrt(static_cast<double>(db.size()));
    if (f == 0) v.difference_seed_se = se;
    if (!(std::abs(d) > kVerdictSeedErrors * se)) v.exceeds_seed = false;
    if (!(std::abs(d) > v.spread_required)) v.exceeds_spread = false;
    for (double x : db)
      if (!(sign(x) == s)) v.same_sign_batches = false;
  }
  v.no_model_describes = context.no_model_describes;
  v.resolved = v.same_sign_fits && v.same_sign_batches && v.exceeds_seed && v.exceeds_spread &&
               !v.no_model_describes;
  v.tie = !v.resolved && std::isfinite(v.difference) && !v.no_model_describes;
  if (v.resolved) v.closer = s < 0 ? a_key : b_key;
  v.text = verdict_text(v, figure, a_name, b_name);
  return v;
}

bool no_model_describes(const std::vector<double>& shape_figures) {
  bool any = false;
  for (double f : shape_figures) {
    if (std::isnan(f)) continue;  // not defined: describes nothing either way
    if (!(f > kNoModelShapeRmsLog)) return false;
    any = true;
  }
  return any;
}

}  // namespace weft
