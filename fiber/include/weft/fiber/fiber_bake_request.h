#pragma once
// `weft bake fiber` and Python's weft.bake_fiber as one request (every option with its default
// stated once), its plan (every check before any work) and its run (the bake, a shard's part or
// a resumed bake; returns what happened and prints nothing), and the merge of a sharded bake's
// parts into its table.
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/job_part.h"
#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft {

// The most passes a request may ask (an interrupted bake keeps the finished ones).
inline constexpr uint64_t kMaxFiberBakePasses = uint64_t{1} << 20;
// The most surface-lobe directions per photon a request may ask.
inline constexpr int kMaxFiberSurfaceSamples = 1024;
// The most threads a request may ask (0: all cores).
inline constexpr int kMaxFiberBakeThreads = 1024;

struct FiberBakeRequest {
  std::string spec;  // a spec file or a preset name
  // A spec the caller has read already (Python's dict): used instead of reading 'spec'.
  std::optional<FiberSpec> spec_read;
  // The table (.exr), or a shard's part file; empty: nothing is written (Python keeps the table).
  std::string output;
  uint64_t photons = FiberTableBakeOptions{}.photons_per_band;
  int resolution = FiberTableBakeOptions{}.resolution;
  std::string bands = name_of(kFiberBakeBands, FiberTableBakeOptions{}.spectral);
  std::string route = name_of(kFiberBakeRoutes, FiberTableBakeOptions{}.route);
  // Not given: the spec's and route's default (fiber_bake_defaults), as are surface_samples and
  // entry.
  std::optional<std::string> estimator;
  bool mirror_fold = FiberTableBakeOptions{}.mirror_fold;
  std::optional<int> surface_samples;
  std::optional<std::string> entry;
  std::string surface_lobe = name_of(kFiberSurfaceLobes, FiberTableBakeOptions{}.surface_lobe);
  uint64_t seed = FiberTableBakeOptions{}.seed;
  uint64_t passes = FiberTableBakeOptions{}.passes;
  int threads = FiberTableBakeOptions{}.threads;
  std::string shard;    // "K/N": only shard K of N's bands, into a part file (empty: all)
  bool resume = false;  // checkpoint every pass beside the output, continue from one there
  // The colour a cloth made of the fiber should have (any --colour form, core/colour_target.h):
  // the spec's dyes are scaled to meet it before the bake, through the cloth of 'colour_weave'
  // (fabric/fiber_colour.h: the fiber bake with a colour is planned and run there, since the
  // reading is a fabric's); "" = the recipe as written.
  std::string colour;
  std::string colour_weave;  // woven sample options (.json) that read the colour; "" = the poplin
  // Written into the table's metadata beside the bake's own keys (a colour match's "colour").
  std::vector<std::pair<std::string, std::string>> table_metadata;
  // How refusals name the options: "--" on the command line ("--surface-samples"), "" in Python
  // ("surface_samples").
  std::string option_prefix;
  RunLimits limits;
};

// An option as the request's front end names it: "--surface-samples" or "surface_samples".
std::string fiber_option_name(const FiberBakeRequest& r, std::string field);

// A request's inputs, read and checked.
struct FiberBakePlan {
  FiberBakeRequest request;
  FiberSpec spec;
  FiberTableBakeOptions options;
  Shard shard;
  UnitRange bands;                    // the bands this run traces
  JobPart job;                        // a part's or checkpoint's identity (when there is an output)
  std::vector<FiberBandState> start;  // from a checkpoint (empty: from the start)
};

// The checks in this order, so that the same error wins whichever front end asks: the output
// guard and the output's name (when there is an output), the spec, every option's range and name,
// the shard, the checkpoint, and the bake's memory and time (check_fiber_bake). weft::Error naming
// the option at fault. 'warn' gets a warning as it arises (an unreadable checkpoint passed over),
// so that a refusal after it still shows it.
FiberBakePlan plan_fiber_bake(const FiberBakeRequest& request,
                              const std::function<void(const std::string&)>& warn = {});

struct FiberBakeHooks {
  ProgressCallback progress = no_progress();
  // Whether the user interrupted the bake: a bake interrupted before its first photon is
  // reported by the library as an error.
  std::function<bool()> interrupted = [] { return false; };
};

struct FiberBakeOutcome {
  bool interrupted_before_work = false;  // nothing traced, nothing written
  bool cancelled = false;                // interrupted after some passes
  bool part_written = false;             // a shard's part (to the request's output)
  // A whole bake's table (written to the output when there is one) and its summary, with exactly
  // the keys of `weft bake fiber --json`.
  std::optional<FiberTableBakeResult> table;
  nlohmann::json summary;
  double seconds = 0;
};

FiberBakeOutcome run_fiber_bake(const FiberBakePlan& plan, const FiberBakeHooks& hooks = {});

// The summary of a bake or of a merge of its shards (the keys of `weft bake fiber --json`).
nlohmann::json fiber_bake_summary(const FiberTableBakeResult& r, const FiberSpec& spec,
                                  const FiberTableBakeOptions& o, const std::string& output,
                                  double seconds);

// The table of a sharded bake from all its parts' units, written to 'output', with its summary.
// The parts are a user's files: every setting is read through the checks a job file gets, so a
// corrupt or crafted part is refused naming the setting.
FiberBakeOutcome merge_fiber_bake_parts(const JobPart& all, const std::string& output);

}  // namespace weft
