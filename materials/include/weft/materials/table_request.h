#pragma once
// weft table: a table's header and figures (info), and an analytic material tabulated as a
// reference (bake), as a request, a plan and a run.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/registry.h"

namespace weft {

// The header and figures of a table: format, resolution, bins, bands, kind, metadata, checksum,
// extremes, and the albedo, reflectance and transmittance for light along the normal and seen
// along the normal (they differ for a non-reciprocal table, e.g. the paper's summed fabric).
nlohmann::json table_info(const TabulatedBsdfTable& table, const std::string& file);

struct TableBakeRequest {
  std::string type;                                // a material type, as in a scene
  std::string params = "{}";                       // its parameters, a JSON object
  std::string output;                              // the table (.exr)
  std::string kind = "fiber";                      // fiber or fabric
  int resolution = 16, samples = 16, threads = 0;  // samples: stratified per cell pair
  uint64_t seed = 1;
  RunLimits limits;
};

struct TableBakePlan {
  TableBakeRequest request;
  nlohmann::json params;
  Bsdf bsdf;
};
// weft::Error naming "--params" (bad JSON, an unknown type or parameter) or the output; the
// output guard over the files the parameters name (a table, a measured network).
TableBakePlan plan_table_bake(const TableBakeRequest& request);
// The RGB table of the material, its metadata naming the material and its hash, the seed and the
// samples; the caller adds its program_version and writes it.
TabulatedBsdfTable run_table_bake(const TableBakePlan& plan, const ProgressCallback& progress);

}  // namespace weft
