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
           (a_closer ? b_name : a_name) + " (" + values + ", difference " + seed +
           ", same sign against all " + fits + " of the measurement and every batch)";
  }
  std::string why;
  if (!std::isfinite(v.difference))
    why = "a figure is not defined";
  else if (!v.same_sign_fits)
    why = "the sign differs between the measurement's fits";
  else if (!v.exceeds_seed)
    why = "within " + fmt(kVerdictSeedErrors, 2) + " seed standard errors";
  else
    why = "the sign differs between batches";
  return figure_name(figure) + ", " + a_name + " vs " + b_name + ": not resolved (" + values +
         ", difference (first minus second) " + fmt(v.difference, 2) + " +- " +
         fmt(v.difference_seed_se, 1) + " seed, " + fmt(lo, 2) + ".." + fmt(hi, 2) +
         " against the " + fits + " of the measurement; " + why + ")";
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
                       const FigureSamples& b) {
  Verdict v;
  v.figure = kFigureKeys[figure];
  v.a = a_key;
  v.b = b_key;
  v.a_value = a.value();
  v.b_value = b.value();
  v.difference = v.a_value - v.b_value;
  const int s = sign(v.difference);
  v.same_sign_fits = v.same_sign_batches = v.exceeds_seed = std::isfinite(v.difference) && s != 0;
  for (size_t f = 0; f < a.mean.size() && f < b.mean.size(); ++f) {
    const double d = a.mean[f] - b.mean[f];
    v.difference_per_fit.push_back(d);
    if (!(sign(d) == s)) v.same_sign_fits = false;
    const std::vector<double> db = batch_differences(a, b, f);
    const double se = db.empty() ? 0.0 : sample_sd(db) / std::sqrt(static_cast<double>(db.size()));
    if (f == 0) v.difference_seed_se = se;
    if (!(std::abs(d) > kVerdictSeedErrors * se)) v.exceeds_seed = false;
    for (double x : db)
      if (!(sign(x) == s)) v.same_sign_batches = false;
  }
  v.resolved = v.same_sign_fits && v.same_sign_batches && v.exceeds_seed;
  if (v.resolved) v.closer = s < 0 ? a_key : b_key;
  v.text = verdict_text(v, figure, a_name, b_name);
  return v;
}

}  // namespace weft
