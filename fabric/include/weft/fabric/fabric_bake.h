#pragma once
// A fabric bake (`weft bake fabric`, weft.bake_fabric) as a request, a plan and a run: what a user
// asks for, with every default stated here once; the plan checks every option rule, file, memory
// and time before any work; the run makes the table (and the weave table), writes what the request
// names and returns what it did, printing nothing.
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/colour_target.h"
#include "weft/core/job_part.h"
#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/fabric/fabric_fibers.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/scenes/weave.h"

namespace weft {

enum class FabricMethod { kSummation, kSummationVisible, kRaytrace };
inline constexpr NameTable<FabricMethod, 3> kFabricMethods{{
    {FabricMethod::kSummation, "summation", "paper's summation"},
    {FabricMethod::kSummationVisible, "summation-visible", "visible-section summation"},
    {FabricMethod::kRaytrace, "raytrace", "fiber-level ray trace"},
}};

// The ray tracer's estimators (--estimator): hero is ChannelSampling::spectral_mis, nee hero with
// the next-event estimate of the exits, mean ChannelSampling::mean.
enum class FabricEstimator { kHero, kNee, kMean };
inline constexpr NameTable<FabricEstimator, 3> kFabricEstimators{{
    {FabricEstimator::kHero, "hero", "hero channel, MIS over channels"},
    {FabricEstimator::kNee, "nee", "hero with next-event estimates of the exits"},
    {FabricEstimator::kMean, "mean", "the channels' mean steers"},
}};

// The summations' direction pairs per cell pair at most (fabric_summation.cpp checks the same).
inline constexpr uint64_t kMaxSummationSamples = 4096;
// --estimator nee's draws per scattering and particles per launch block unless given
// (docs/PERFORMANCE.md).
inline constexpr int kDefaultNextEventRays = 1, kDefaultLaunchLattice = 13;
// The weave table's position cells per side and coarse R unless given (docs/fabric-bsdf.md, "The
// weave table": its noise and cost on the bundled poplin).
inline constexpr int kDefaultWeavePositions = 8, kDefaultWeaveResolution = 4;

// What a user asks of a fabric bake; the fields are the command line's options. Options not given
// are empty strings or std::nullopt: the method's default then applies, and an option that does
// nothing with the method given is refused.
struct FabricBakeRequest {
  std::string fiber = "red-cotton";  // fiber table (.exr), or a spec or preset baked on first use
  // --fiber's table when the caller holds it already (Python's Table): 'fiber' only names it.
  std::shared_ptr<const TabulatedBsdfTable> fiber_table;
  std::string warp_fiber, weft_fiber;  // per-yarn fibers (raytrace); "" = fiber
  bool thread_colours = false;         // a fiber per colour of the WIF draft's threads
  // How each thread colour dyes --fiber (kThreadColourMethods); not given: match.
  std::optional<std::string> thread_colour_method;
  // The colour the cloth should have (core/colour_target.h): --fiber's dyes are scaled to meet
  // it (fabric_colour.h); "" = the recipe as written.
  std::string colour;
  std::string method = name_of(kFabricMethods, FabricMethod::kSummation);
  std::string weave;                          // woven sample options (.json); "" = bundled poplin
  std::optional<WeaveOptions> weave_options;  // in place of the file (Python's dict)
  std::string pattern, wif;                   // over the sample's; "" = not given
  // "yarn" or "fiber" over the sample's own; not given: the sample's, else yarn (a felt's file
  // says fiber, its only detail).
  std::optional<std::string> detail;
  int resolution = 8;                           // fabric table bins per hemisphere side
  std::optional<uint64_t> samples;              // the method's default unless given
  std::optional<std::string> estimator;         // kFabricEstimators; hero unless given
  std::optional<int> next_event_rays;           // nee: kDefaultNextEventRays unless given
  std::optional<int> launch_lattice;            // nee: kDefaultLaunchLattice unless given
  std::optional<std::string> straight_through;  // kStraightThroughNames; the library's default
  std::optional<double> split_threshold;        // the library's default unless given
  std::optional<int> max_scatterings;           // the library's default unless given
  std::string weave_out;                        // the weave table (.exr); "" = no weave tally
  std::optional<std::string> weave_positions;   // "N" or "UxV"; kDefaultWeavePositions
  std::optional<int> weave_resolution;          // kDefaultWeaveResolution (at most R)
  // The sheen booked apart (FabricRaytraceOptions::sheen_h_resolution; not given: off), its
  // window and its light bins (the library's defaults unless given).
  std::optional<int> sheen_resolution, sheen_window, sheen_light_resolution;
  std::optional<std::string> sheen_light;  // kSheenLightNames; the library's default
  uint64_t seed = 1;
  int threads = 0;     // 0 = all cores; results do not depend on it
  std::string output;  // the fabric table (.exr), or a shard's part; "" = returned, not written
  std::string shard;   // "K/N" (raytrace); "" = the whole table
  bool resume = false;
  // Named in the table's program_version after the version ("weft 1.2 (python)"); "" = none.
  std::string front_end;
  RunLimits limits;
};

// The request checked, with what the run needs from the checks.
struct FabricBakePlan {
  FabricBakeRequest request;
  FabricMethod method = FabricMethod::kSummation;
  FabricRaytraceOptions raytrace;  // the ray tracer's settings (its defaults for a summation)
  FabricFiberOptions fibers;
  std::optional<ColourTarget> colour;  // the request's colour, parsed
  WeaveOptions weave;                  // the sample's, its tessellation fitted to the memory budget
  std::string note;                    // why the tessellation was coarsened; "" when it was not
  double scene_bytes = 0;              // the scene's memory estimate (0 for the paper's summation)
};

// Every check before any work, in this order (the first error wins): the options that need
// another method, the ray tracer's settings, the per-yarn fibers, the output guard, the output's
// extension, the time, the scene's memory. weft::Error naming the option.
FabricBakePlan plan_fabric_bake(const FabricBakeRequest& request);

struct FabricBakeHooks {
  ProgressCallback progress = no_progress();
  // A checkpoint passed over ("... is unreadable; starting afresh"), said as it happens.
  std::function<void(const std::string&)> warning = [](const std::string&) {};
};

struct FabricBakeResult {
  bool cancelled = false;  // nothing written (with --resume, the last checkpoint stays)
  // A shard's part was written to the output: its incident bins.
  std::optional<UnitRange> part_units;
  Shard shard;
  TabulatedBsdfTable table;         // as written
  std::optional<WeaveTable> weave;  // with weave_out, as written
  nlohmann::json summary;           // --json's summary
  // Lines for the user (a part's weave tally and how to merge it).
  std::vector<std::string> notes;
};

// The run of a plan: the woven sample, the fiber tables (baked into ./.weft-cache on first use),
// the table by the plan's method, written to the request's output and weave_out.
FabricBakeResult run_fabric_bake(const FabricBakePlan& plan, const FabricBakeHooks& hooks);

// A summation plan's table of 'sample' made of 'fiber' (the plan's method, resolution, samples,
// seed and threads); nothing when 'progress' said stop (summation-visible's scene and rays poll
// it, as the table's rows do).
std::optional<TabulatedBsdfTable> summed_fabric_table(const FabricBakePlan& plan,
                                                      const WovenSample& sample,
                                                      const TabulatedBsdfTable& fiber,
                                                      const ProgressCallback& progress);

// `weft merge` of a ray trace's parts ('all', merge_job_parts): the table written to 'output' and
// the weave table to 'weave_out' (which the parts must carry exactly when given); the summary.
nlohmann::json merge_fabric_parts(const JobPart& all, const std::string& output,
                                  const std::string& weave_out);

// The time check before a fabric bake of 'method': check_long_work at the method's least rate
// for a ray trace of 'bins_traced' incident bins x 'samples' particles, or a summation of every
// cell pair x 'samples' direction pairs (the method's default when not given).
void check_fabric_bake(const RunLimits& limits, FabricMethod method, int resolution,
                       uint64_t bins_traced, std::optional<uint64_t> samples, int threads,
                       const std::string& samples_field);

}  // namespace weft
