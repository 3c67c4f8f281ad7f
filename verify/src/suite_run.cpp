// weft verify --suite's plan and run (suite.h): every fabric checked before the first runs.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/verify/report.h"
#include "weft/verify/suite.h"
#include "weft/verify/whole_run.h"

namespace weft {

VerifySuitePlan plan_verify_suite(const VerifyRequest& base, const std::string& suite_file,
                                  const RunLimits& limits) {
  VerifySuitePlan p;
  p.base = base;
  p.suite = read_verify_suite(suite_file.empty() ? bundled_verify_suite()
                                                 : std::filesystem::path(suite_file));
  std::vector<NamedPath> inputs = {{p.suite.file.string(), "suite file"}};
  for (const SuiteFabric& f : p.suite.fabrics) {
    inputs.push_back({f.measured, f.name + "'s measured CSV"});
    inputs.push_back({f.weave, f.name + "'s weave options"});
    inputs.push_back({f.wif, f.name + "'s WIF draft"});
    inputs.push_back({f.fiber, f.name + "'s fiber table or spec"});
  }
  validate_output_paths(limits, {}, inputs, {{base.output, "-o"}});
  check_suite_output(base.output);
  for (size_t k = 0; k < p.suite.fabrics.size(); ++k) {
    const SuiteFabric& f = p.suite.fabrics[k];
    // Every fabric is planned before the first runs: the error says which one.
    try {
      p.plans.push_back(plan_verify(suite_request(f, base, base.output)));
    } catch (const Error& e) {
      throw Error(p.suite.file.string(), "fabrics[" + std::to_string(k) + "]",
                  "'" + f.name + "': " + e.what());
    }
    // The draft a fabric's weave options name is read too.
    if (p.plans.back().weave.wif)
      validate_output_paths(limits, {}, {{*p.plans.back().weave.wif, f.name + "'s WIF draft"}},
                            {{base.output, "-o"}});
    const VerifyEstimate e = estimate_verify(p.plans.back());
    p.total.typical += e.typical;
    p.total.least += e.least;
    p.total.cores = e.cores;
    // The fabrics run one after another: the largest scene is the suite's.
    p.total.scene_bytes = std::max(p.total.scene_bytes, e.scene_bytes);
  }
  return p;
}

std::string verify_suite_estimate_text(const VerifySuitePlan& p) {
  char b[512];
  std::snprintf(b, sizeof b,
                "weft verify --suite: %zu fabrics of %s, quality %s: about %s on %u cores\n",
                p.plans.size(), p.suite.file.string().c_str(), p.base.quality.c_str(),
                format_seconds(p.total.typical / p.total.cores).c_str(), p.total.cores);
  return b;
}

void check_verify_suite_time(const VerifySuitePlan& p, const RunLimits& limits) {
  check_memory(limits, p.total.scene_bytes, p.suite.file.string(), "weave",
               "the largest fabric's ray-traced scene");
  check_long_work(limits, p.total.least, 1.0, p.base.threads, "", "--quality",
                  "weft verify --suite at quality " + p.base.quality, kVerifyLeastRates);
}

namespace {

// The last fabric's woven sample, handed on to the next fabric of the same weave options: the
// bundled suite's 24 fabrics share three samples, and a felt's mat takes seconds to make. One is
// kept at a time, so the suite holds no more than its largest fabric does.
class LastSample {
 public:
  std::shared_ptr<const WovenSample> get(const WeaveOptions& options,
                                         const ProgressCallback& progress) {
    if (sample_ && options == options_) return sample_;
    sample_.reset();
    auto made = std::make_shared<const WovenSample>(make_woven_sample(options, progress));
    if (!made->cancelled) sample_ = made, options_ = options;
    return made;
  }

 private:
  WeaveOptions options_;
  std::shared_ptr<const WovenSample> sample_;
};

}  // namespace

VerifySuiteOutcome run_verify_suite(const VerifySuitePlan& p, const VerifySuiteHooks& hooks) {
  std::filesystem::create_directories(p.base.output);
  VerifySuiteOutcome out;
  LastSample last;
  for (size_t k = 0; k < p.plans.size(); ++k) {
    SuiteRow row{p.suite.fabrics[k], nullptr, ""};
    hooks.starting(k);
    try {
      VerifyHooks fabric = hooks.fabric(k);
      fabric.sample = [&last, progress = fabric.progress](const WeaveOptions& o) {
        return last.get(o, progress);
      };
      const VerifyOutcome run = run_verify_plan(p.plans[k], fabric);
      if (run.cancelled) {
        out.cancelled = true;
        return out;
      }
      row.metrics = verify_metrics(run.report);
    } catch (const Error& e) {
      row.error = e.what();
      out.failed = true;
      hooks.failed(k, e.what());
    }
    out.rows.push_back(std::move(row));
  }
  const std::filesystem::path dir = p.base.output;
  write_text_atomically(dir / "suite.json", verify_suite_json(p.suite, out.rows));
  write_text_atomically(dir / "index.html", verify_suite_html(p.suite, out.rows));
  return out;
}

}  // namespace weft
