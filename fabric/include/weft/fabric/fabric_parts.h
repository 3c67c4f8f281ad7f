#pragma once
// The fiber-level ray trace in pieces (`weft bake fabric --method raytrace --shard/--resume`,
// `weft merge`): parts of incident bins, checkpoints, and the table assembled from them.
#include <functional>
#include <optional>
#include <string>

#include "weft/core/job_part.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/weave_tally.h"

namespace weft {

// The ray tracer's splits and roulette kills in the table's metadata (whole runs and merges).
void record_particle_counts(TabulatedBsdfTable& t, uint64_t splits, uint64_t roulette_kills);

// What a ray trace in pieces did: returned the whole table ('result'), wrote a shard's part
// (incident bins 'units' of shard 'shard' to the output), or was cancelled (nothing written; with
// --resume the last checkpoint stays to continue from).
struct FabricPiecesOutcome {
  std::optional<FabricRaytraceResult> result;
  bool cancelled = false;
  bool part_written = false;
  UnitRange units;
  Shard shard;
};

// With --shard K/N: traces the shard's incident bins and writes them as a part to 'output'.
// 'inputs' (input_file_hashes of the weave options and draft) joins the job's identity, and so do
// per-yarn fiber tables' checksums and maps (one distinct table: the single-table job, its
// identity unchanged). With --resume: checkpoints every finished piece beside 'output' and starts
// from a checkpoint left there (an unreadable one is passed over, said through 'warning'); a
// whole table is returned for the caller to write. 'recorded_inputs' (input_file_hashes of the
// fiber tables or specs and a draft the weave options name) goes into a part's extra as
// kPartInputFilesKey, outside its identity, for weft merge to guard and check.
FabricPiecesOutcome raytrace_fabric_in_pieces(
    const WovenSample& sample, const nlohmann::json& inputs, const FiberTables& fibers,
    const FabricRaytraceOptions& r, const std::string& output, const std::string& shard,
    bool resume, const ProgressCallback& progress,
    const std::function<void(const std::string&)>& warning,
    const nlohmann::json& recorded_inputs = nlohmann::json::object());

// The unit of incident bin 'bin' of a ray trace (its row of the table, its books and noise, every
// value with its exact bits); the channels of such a unit for a table of 'bins' bins; and the
// whole result (table, books, noise summed as raytrace_fabric_table sums them) from the units
// [first_unit, first_unit + bins) of all its bins, with the weave table when the units carry the
// weave tally of that shape. weft::Error naming a missing or malformed unit.
void encode_fabric_bin(const FabricRaytraceResult& result, uint64_t bin, std::vector<double>& unit);
int fabric_bin_channels(const std::vector<double>& unit, uint64_t bins);
// The whole table (with the pieces' metadata and particle counts) of a merged job of every bin;
// its resolution, channels and weave from the job, each checked before anything is sized.
FabricRaytraceResult assemble_fabric_job(const JobPart& all);
FabricRaytraceResult assemble_fabric_bins(const std::map<uint64_t, std::vector<double>>& units,
                                          uint64_t first_unit, uint64_t bins, int resolution,
                                          int channels, const WeaveShape& weave = {});

// What `bake fabric --json` and `merge --json` print of a ray trace (books, counts, noise) and of a
// fabric table (resolution, sample, albedo at normal incidence): one list of keys for both.
nlohmann::json raytrace_summary(const FabricRaytraceResult& result);
nlohmann::json fabric_table_summary(const TabulatedBsdfTable& table);
// What a ray trace's run says 1 % relative noise per channel costs: its CPU seconds and
// particles per incident bin scaled by (noise / 0.01)^2, the noise falling as 1/sqrt(particles)
// (the particles are independent; the computed straight-through light's rays grow with them).
// Null per channel where the channel has no noise to scale (no signal). weft::Error for CPU
// seconds or particles that are not positive and finite.
nlohmann::json noise_cost_summary(const std::vector<double>& relative_noise_per_channel,
                                  uint64_t particles_per_bin, double cpu_seconds);

}  // namespace weft
