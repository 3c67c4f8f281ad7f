#pragma once
// weft sweep's request, plan and run: what a user asks for (a front end binds
// these fields as they are), the gonioreflectometer settings it becomes over the scene's sweep
// once every rule, file and time estimate is checked, and the run: the whole sweep to a CSV, or a
// shard's views to a part file (core/job_part.h), checkpointed and resumed on request. The run
// prints nothing.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/job_part.h"
#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/integrators/gonio.h"
#include "weft/integrators/render_request.h"
#include "weft/materials/registry.h"

namespace weft {

// What a user asks of weft sweep. Unset values and empty strings are options not given (the
// scene's sweep then applies).
struct SweepRequest {
  std::string scene;   // scene description (.json)
  std::string output;  // the CSV, or a shard's part file
  std::optional<double> light_zenith_deg, light_azimuth_deg, view_azimuth_deg;
  std::string view_zenith_deg;  // "a:b:step", "a,b,c" or one value
  std::string sample;           // object to measure
  std::optional<double> irradiance;
  std::string normalize_to;  // one value or "r,g,b"
  bool white_check = true;
  std::optional<int> spp, resolution;
  std::optional<uint64_t> seed;
  int threads = GonioSettings{}.threads;
  std::string shard;    // "K/N" (empty: the whole sweep)
  bool resume = false;  // checkpoint beside the output, and continue from one
  RunLimits limits;
};

struct SweepPlan {
  SweepRequest request;
  SceneDescription description;
  GonioSettings settings;  // a partial run's: the units still to render
  Shard shard;
  JobPart job;               // what fixes the sweep's bits, and its units
  UnitRange range;           // the shard's units
  GonioResult done;          // the units a checkpoint holds
  std::vector<size_t> todo;  // the shard's other units: this run renders them
  bool partial = false;      // a shard or a resumable run: units, not the whole sweep at once
  bool renders = true;       // false when a checkpoint holds every unit: nothing to render
};

// weft::Error naming the option (or the file and field) at fault, in this order: the scene and
// its sweep, a missing light or view zenith, bad views or normalization, an output that is an
// input or unwritable, a bad shard, an unreadable input, a checkpoint of another sweep, work too
// long without limits.yes_long. An unreadable checkpoint is passed over with a warning.
SweepPlan plan_sweep(const SweepRequest& request, const ScenePlanHooks& hooks = {});

struct SweepHooks {
  ProgressCallback progress = no_progress();
  FiberTableResolver fiber_tables;  // null: materials that name a fiber spec are an error
};

struct SweepOutcome {
  // The views this run rendered: rays, dropped samples; cancelled: nothing was written.
  RenderOutcome rendered;
  // The whole sweep, written as the request's CSV; none for a shard, whose part file was written.
  std::optional<GonioResult> table;
};

SweepOutcome run_sweep(const SweepPlan& plan, const SweepHooks& hooks = {});

// weft merge of a sweep's parts: the table from all of the job's units (as run_sweep gives it in
// one piece), written as a CSV to 'output'.
GonioResult merge_sweep_parts(const JobPart& all, const std::filesystem::path& output);

}  // namespace weft
