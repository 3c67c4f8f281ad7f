#pragma once
// The models a verification sets beside the measurement, in one table: each model's key in
// metrics.json, the prefix of its headline figures there, and the names the report, the suite's
// page and the verdicts give it. Every file that names a model reads it here.
#include <array>
#include <string>

namespace weft {

enum class VerifyModel {
  kComputedRaytrace,
  kComputedSummation,
  kClassic,
  kComputedRaytraceFitted,
  kClassicFitted
};

struct VerifyModelNames {
  VerifyModel model;
  const char* key;          // metrics.json "models" key, ModelCurves::key
  const char* headline;     // prefix of its top-level figures ("computed_shape_rms_log")
  const char* label;        // the report's legend (a fitted model adds ", fitted")
  const char* short_label;  // the suite's page and its terminal lines
  const char* verdict;      // in a verdict's words (a fitted model: "the fitted ...")
};

// In the report's order; the fitted models are the first and third with "_fitted" keys.
inline constexpr std::array<VerifyModelNames, 5> kVerifyModels{{
    {VerifyModel::kComputedRaytrace, "computed_raytrace", "computed",
     "computed (fiber-level ray trace)", "computed (ray trace)", "computed model (ray trace)"},
    {VerifyModel::kComputedSummation, "computed_summation", "summation",
     "computed (paper's summation)", "computed (paper's summation)",
     "computed model (paper's summation)"},
    {VerifyModel::kClassic, "classic", "classic", "classic (Lambert + Cook-Torrance)",
     "classic (Lambert + Cook-Torrance)", "classic model"},
    {VerifyModel::kComputedRaytraceFitted, "computed_raytrace_fitted", "computed_fitted",
     "computed (fiber-level ray trace), fitted", "computed (ray trace), fitted",
     "fitted computed model (ray trace)"},
    {VerifyModel::kClassicFitted, "classic_fitted", "classic_fitted",
     "classic (Lambert + Cook-Torrance), fitted", "classic (Lambert + Cook-Torrance), fitted",
     "fitted classic model"},
}};

inline const VerifyModelNames& verify_model(VerifyModel m) {
  return kVerifyModels[static_cast<size_t>(m)];
}
inline const char* verify_model_key(VerifyModel m) {
  return verify_model(m).key;
}
// Whether 'key' is a fitted model's (its colour and shape set by a fit to the measurement): the
// table's fitted rows and any other model fitted, all keyed "<model>_fitted" (fit_run.cpp).
inline constexpr const char* kFittedKeySuffix = "_fitted";
inline bool is_fitted_model(const std::string& key) {
  const std::string suffix = kFittedKeySuffix;
  return key.size() > suffix.size() &&
         key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace weft
