// The report's verdicts: which models are compared, and their names in words.
#include <algorithm>

#include "weft/verify/models.h"
#include "weft/verify/report.h"

namespace weft {

std::string verdict_model_name(const std::string& key) {
  for (const VerifyModelNames& m : kVerifyModels)
    if (key == m.key) return std::string("the ") + m.verdict;
  // A model of no row ("computed_summation_fitted"): its base's name, fitted.
  const bool is_fitted = is_fitted_model(key);
  const std::string base =
      is_fitted ? key.substr(0, key.size() - std::string(kFittedKeySuffix).size()) : key;
  for (const VerifyModelNames& m : kVerifyModels)
    if (base == m.key) return std::string("the fitted ") + m.verdict;
  return "the " + std::string(is_fitted ? "fitted " : "") + base;
}

VerifyVerdictContext verify_verdict_context(const VerifyReport& r) {
  VerifyVerdictContext c;
  if (const auto normal = normal_index(r.measured))
    c.measured_spread = measured_fit_spread(r.measured, *normal);
  std::vector<double> shape;
  for (const ModelCurves& m : r.models)
    if (!m.figures.fits.empty()) shape.push_back(m.figures.figure[kShapeFigure].value());
  c.no_model_describes = no_model_describes(shape);
  return c;
}

std::vector<Verdict> verify_verdicts(const VerifyReport& r) {
  const auto find = [&](const std::string& key) -> const ModelCurves* {
    const auto it = std::find_if(r.models.begin(), r.models.end(),
                                 [&](const ModelCurves& m) { return m.key == key; });
    return it == r.models.end() ? nullptr : &*it;
  };
  using M = VerifyModel;
  const std::pair<const char*, const char*> pairs[] = {
      {verify_model_key(M::kComputedRaytrace), verify_model_key(M::kClassic)},
      {verify_model_key(M::kComputedSummation), verify_model_key(M::kClassic)},
      {verify_model_key(M::kComputedRaytraceFitted), verify_model_key(M::kClassicFitted)}};
  const VerifyVerdictContext context = verify_verdict_context(r);
  std::vector<Verdict> out;
  for (int f = 0; f < 3; ++f)
    for (const auto& [ka, kb] : pairs) {
      const ModelCurves* a = find(ka);
      const ModelCurves* b = find(kb);
      if (!a || !b || a->figures.fits.empty() || b->figures.fits.empty()) continue;
      const auto kind = static_cast<FigureKind>(f);
      Verdict v = compare_figure(kind, ka, verdict_model_name(ka), a->figures.figure[f], kb,
                                 verdict_model_name(kb), b->figures.figure[f],
                                 {context.measured_spread[f], context.no_model_describes});
      // Calibrated, both models' colour was set from the measurement's own d/8 reading, in the
      // measurement's space: what the absolute figure then judges is everything that one reading
      // does not set (the angles, the dye's spectral shape), which any RGB space shows.
      if (kind == kAbsoluteFigure && r.colour_calibrated) {
        v.text += " [calibrated: the colour from the measurement's own d/8 reading]";
      } else if (kind == kAbsoluteFigure && !absolute_judged(r)) {
        v.comparable = false;
        v.text += " [" + not_comparable_note(r.measured.colour_space) + "]";
      }
      out.push_back(std::move(v));
    }
  return out;
}

}  // namespace weft
