#include "weft/fabric/fabric_bake.h"

#include "weft/core/direction_grid.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"

namespace weft {

void check_fabric_bake(const RunLimits& limits, FabricMethod method, int resolution,
                       uint64_t bins_traced, std::optional<uint64_t> samples, int threads,
                       const std::string& samples_field) {
  if (method == FabricMethod::kRaytrace) {
    const uint64_t per_bin = samples.value_or(FabricRaytraceOptions{}.particles_per_bin);
    check_long_work(limits, double(bins_traced) * double(per_bin), kMinSecondsPerFabricParticle,
                    threads, "", samples_field,
                    "a ray trace of " + std::to_string(bins_traced) + " incident bins x " +
                        std::to_string(per_bin) + " particles",
                    "0.25 us per particle per core at least");
    return;
  }
  const uint64_t bins = static_cast<uint64_t>(DirectionGrid{resolution}.bins());
  const uint64_t per_cell = samples.value_or(FabricSummationOptions{}.samples_per_cell);
  const bool visible = method == FabricMethod::kSummationVisible;
  check_long_work(
      limits, double(bins * bins) * double(per_cell),
      visible ? kMinSecondsPerVisiblePair : kMinSecondsPerPaperPair, threads, "", samples_field,
      std::string("a ") + name_of(kFabricMethods, method) + " of " + std::to_string(bins * bins) +
          " cell pairs x " + std::to_string(per_cell) + " direction pairs",
      visible ? "5 us per direction pair per core at least"
              : "0.1 us per direction pair per core at least");
}

}  // namespace weft
