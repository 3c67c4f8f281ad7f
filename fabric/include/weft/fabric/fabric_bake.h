#pragma once
// What `weft bake fabric` and weft.bake_fabric share: the methods that make a fabric table, by
// name, and the check of a bake's time before any work.
#include <cstdint>
#include <optional>
#include <string>

#include "weft/core/names.h"
#include "weft/core/run_limits.h"

namespace weft {

enum class FabricMethod { kSummation, kSummationVisible, kRaytrace };
inline constexpr NameTable<FabricMethod, 3> kFabricMethods{{
    {FabricMethod::kSummation, "summation", "paper's summation"},
    {FabricMethod::kSummationVisible, "summation-visible", "visible-section summation"},
    {FabricMethod::kRaytrace, "raytrace", "fiber-level ray trace"},
}};

// The time check before a fabric bake of 'method': check_long_work at the method's least rate
// for a ray trace of 'bins_traced' incident bins x 'samples' particles, or a summation of every
// cell pair x 'samples' direction pairs (the method's default when not given).
void check_fabric_bake(const RunLimits& limits, FabricMethod method, int resolution,
                       uint64_t bins_traced, std::optional<uint64_t> samples, int threads,
                       const std::string& samples_field);

}  // namespace weft
