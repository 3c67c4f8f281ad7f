#pragma once
// weft verify --suite (docs/verify.md "Suite"): every bundled measurement verified with the
// description of its sample (construction, fiber, colour space), and one page over all of them.
// The suite file (verify/data/suite.json) lists the fabrics; each runs as its own weft verify
// into a folder of the suite's output, and the page and suite.json are made from their
// metrics.json files.
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/core/run_limits.h"
#include "weft/verify/plan.h"
#include "weft/verify/whole_run.h"

namespace weft {

// One fabric of a suite: its measurement and what is known of the sample, as verify options.
// Paths are resolved against the suite file's folder; 'fiber' is a preset name when no such
// file exists (as --fiber).
struct SuiteFabric {
  std::string name;          // a folder name: letters, digits, '-', '_', '.'
  std::string measured;      // the measured in-plane table
  std::string fiber;         // spec, preset or baked table
  std::string weave;         // sample options (.json), or empty
  std::string pattern;       // over the sample's, or empty
  std::string wif;           // over the sample's, or empty
  std::string colour_space;  // of the measurement, or empty: as its file says
  std::string known;         // what the source says of the sample, in words
};

struct VerifySuite {
  std::filesystem::path file;
  std::string title;
  std::vector<SuiteFabric> fabrics;
};

// Reads a suite file; weft::Error naming the file and field (fabrics[2].measured) for a bad or
// missing field, an unknown key, a repeated or unsafe name, or a missing measured file.
VerifySuite read_verify_suite(const std::filesystem::path& file);
// The bundled suite (verify/data/suite.json).
std::filesystem::path bundled_verify_suite();

// The request of one fabric: 'base' (quality, seed, threads) with the fabric's inputs, writing
// into 'output' / name.
VerifyRequest suite_request(const SuiteFabric& fabric, const VerifyRequest& base,
                            const std::filesystem::path& output);

// A fabric's outcome: its metrics.json (null when it failed) or the error that stopped it.
struct SuiteRow {
  SuiteFabric fabric;
  nlohmann::json metrics;
  std::string error;
};
// The suite's summary (suite.json: "report": "weft verify suite", a row per fabric with each
// model's figures and the verdicts) and its page (index.html linking every fabric's report).
std::string verify_suite_json(const VerifySuite& suite, const std::vector<SuiteRow>& rows);
std::string verify_suite_html(const VerifySuite& suite, const std::vector<SuiteRow>& rows);
// The figures as plain lines, for a terminal.
std::string verify_suite_text(const std::vector<SuiteRow>& rows);

// The suite's output folder must not exist, be empty, or hold an earlier suite (its suite.json
// says so); weft::Error naming it otherwise.
void check_suite_output(const std::filesystem::path& dir);

// A suite run's plan: every fabric planned (inputs read and checked), the output guard over all
// their inputs and the output folder checked, the whole suite's time estimated, before any work.
struct VerifySuitePlan {
  VerifySuite suite;
  VerifyRequest base;  // quality, seed, threads and the output folder
  std::vector<VerifyPlan> plans;
  VerifyEstimate total;
};
// 'suite_file' empty: the bundled suite.
VerifySuitePlan plan_verify_suite(const VerifyRequest& base, const std::string& suite_file,
                                  const RunLimits& limits);
// "weft verify --suite: N fabrics of FILE, quality Q: about T on C cores\n".
std::string verify_suite_estimate_text(const VerifySuitePlan& plan);
// The suite's time at the fastest rates: above an hour needs limits.yes_long (check_long_work).
void check_verify_suite_time(const VerifySuitePlan& plan, const RunLimits& limits);

struct VerifySuiteHooks {
  // The hooks of fabric k's run (its progress, plots, notes).
  std::function<VerifyHooks(size_t k)> fabric;
  // Before fabric k's run, and when it failed (the suite goes on with the next).
  std::function<void(size_t k)> starting = [](size_t) {};
  std::function<void(size_t k, const std::string& error)> failed = [](size_t, const std::string&) {
  };
};
struct VerifySuiteOutcome {
  bool cancelled = false;  // the finished fabrics' reports stay; the page was not written
  bool failed = false;     // some fabric failed (its row holds the error)
  std::vector<SuiteRow> rows;
};
// One report per fabric in the output folder, then suite.json and index.html over them.
VerifySuiteOutcome run_verify_suite(const VerifySuitePlan& plan, const VerifySuiteHooks& hooks);

}  // namespace weft
