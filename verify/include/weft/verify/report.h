#pragma once
// The report of a verification (docs/verify.md "Report"): its files as text, and the folder that
// holds them, written whole or not at all.
#include <array>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/verify/run.h"
#include "weft/verify/verdict.h"

namespace weft {

// The report's files, as text: the long-form curves CSV and metrics JSON (stable keys,
// docs/verify.md), and the offline HTML page embedding the given images (file name -> bytes).
std::string verify_inplane_csv(const VerifyReport& report);
// metrics.json as a value (verify_metrics_json is its text).
nlohmann::json verify_metrics(const VerifyReport& report);
std::string verify_metrics_json(const VerifyReport& report);
std::string verify_index_html(const VerifyReport& report,
                              const std::vector<std::pair<std::string, std::string>>& images);

// The report's verdicts (verify/verdict.h), figure by figure (kFigureKeys' order): the computed
// ray trace against the classic model, the paper's summation against the classic model, and the
// fitted ray trace against the fitted classic model, each where both are in the report.
std::vector<Verdict> verify_verdicts(const VerifyReport& report);
// What the report's verdicts know beyond the models' figures: the measurement's own spread per
// figure (kFigureKeys' order; NaN with one fit) and whether no model describes it (every
// model's shape figure above kNoModelShapeRmsLog).
struct VerifyVerdictContext {
  std::array<double, 3> measured_spread{std::numeric_limits<double>::quiet_NaN(),
                                        std::numeric_limits<double>::quiet_NaN(),
                                        std::numeric_limits<double>::quiet_NaN()};
  bool no_model_describes = false;
};
VerifyVerdictContext verify_verdict_context(const VerifyReport& report);
// A model's name in the verdict's words ("computed (ray trace)", "classic, fitted").
std::string verdict_model_name(const std::string& key);

// Writes DIR whole or not at all: the renders (render_verify_samples: fabric-*.exr, render-*.exr
// and .png), the previews (write_verify_previews), inplane.csv and metrics.json into a staging
// folder beside DIR, then draw(staging) (the plots: inplane-*.png and .svg files it writes there),
// then index.html embedding the plots and linking the renders by relative path, then the staging
// folder replaces DIR. DIR must not exist, be empty, or hold an earlier report (its metrics.json
// has "report": "weft verify"); anything else is refused (weft::Error naming DIR) and left alone.
// The check write_verify_report makes first, for callers to make before the work.
void check_verify_output(const std::filesystem::path& dir);
// The preview page of each fabric table the report holds (computed, classic: the page weft view
// writes, the glTF fit in 3-D beside the table's curves), preview-MODEL.html in 'folder'. Linked
// from index.html rather than embedded: each page inlines three.js and the meshes (about 2 MB), so
// embedding would make index.html several times its size and repeat three.js per model. Without
// the viewer (scripts/install-viewer.sh) none is written and 'skipped' says why: the report is
// the verification, the preview an aid.
std::vector<VerifyPreview> write_verify_previews(const std::filesystem::path& folder,
                                                 const VerifyReport& report, std::string* skipped);
// The renders poll 'progress', and it is asked again between the later steps; when it says stop,
// nothing is written (the staging folder is removed, an earlier report left as it was) and the
// return is false.
bool write_verify_report(const std::filesystem::path& dir, const VerifyReport& report,
                         const std::function<void(const std::filesystem::path& staging)>& draw,
                         const ProgressCallback& progress = no_progress());

}  // namespace weft
