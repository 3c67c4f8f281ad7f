#pragma once
// `weft bake fabric --method raytrace` in pieces (fabric_parts.cpp).
#include <optional>
#include <string>

#include "job_part.h"
#include "weft/integrators/fabric_raytrace.h"

namespace weft::cli {

// The ray tracer's splits and roulette kills in the table's metadata (whole runs and merges).
void record_particle_counts(TabulatedBsdfTable& t, uint64_t splits, uint64_t roulette_kills);

// With --shard K/N: traces the shard's incident bins and writes them as a part to 'output'
// (returns nothing). With --resume: checkpoints every finished piece beside 'output' and starts
// from a checkpoint left there; a whole table is returned for the caller to write. A cancelled
// run returns nothing with exit code 130.
std::optional<FabricRaytraceResult> raytrace_fabric_in_pieces(
    const WovenSample& sample, const TabulatedBsdfTable& fiber, const FabricRaytraceOptions& r,
    const std::string& output, const std::string& shard, bool resume,
    const ProgressCallback& progress, int* exit_code);

}  // namespace weft::cli
