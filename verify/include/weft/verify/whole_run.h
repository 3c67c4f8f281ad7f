#pragma once
// weft verify's whole run from its plan (plan.h, docs/verify.md): the woven sample, the fiber
// (baked through the bake cache, or the given table) and the classic baseline; then either a
// shard's ray traces into a part file, or the summation, run_verify, the fit and the report
// folder. The front end brings the progress, the plots and the lines to show between steps; the
// run returns what happened and prints nothing.
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "weft/core/job_part.h"
#include "weft/core/progress.h"
#include "weft/verify/plan.h"
#include "weft/verify/verify.h"

namespace weft {

struct VerifyHooks {
  ProgressCallback progress = no_progress();
  // Whether the user interrupted the run: the bake cache reports an interrupted bake as an error.
  std::function<bool()> interrupted = [] { return false; };
  // A line to show between steps ("weft: fitting the classic model"), with its newlines.
  std::function<void(const std::string& line)> note = [](const std::string&) {};
  // The plots, drawn into the report's staging folder (write_verify_report).
  std::function<void(const std::filesystem::path& staging)> draw =
      [](const std::filesystem::path&) {};
  // When the run began, for the report's "total_before_report" seconds.
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  // The woven sample of the plan's weave options (a cancelled one when stopped); unset: made by
  // the run. The suite hands on the last fabric's sample to the next one of the same options.
  std::function<std::shared_ptr<const WovenSample>(const WeaveOptions&)> sample;
};

struct VerifyOutcome {
  bool cancelled = false;  // interrupted: nothing was written
  // A sharded run's part (written to the request's output): its job and the units it holds.
  std::optional<JobPart> part;
  UnitRange part_units;
  VerifyReport report;  // the whole run's, as written
};

// The run of a plan; 'all' (a merge): every unit of a sharded job's ray traces, whose inputs must
// still be those the shards read (weft::Error naming "parts" otherwise).
VerifyOutcome run_verify_plan(const VerifyPlan& plan, const VerifyHooks& hooks,
                              const JobPart* all = nullptr);

// --fit: both models fitted with the same objective and budget on their inner models, then the
// fitted parameters evaluated at the run's quality (run_verify again) as the "_fitted" models,
// added to 'report' with the fits. False when interrupted ('report' then incomplete).
bool fit_verify_models(const VerifyPlan& plan, const WovenSample& sample, const VerifyInputs& base,
                       VerifyReport& report, const VerifyHooks& hooks);

}  // namespace weft
