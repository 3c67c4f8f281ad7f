#pragma once
// Materials by name: one explicit name -> factory table (no static self-registration). The error
// for an unknown name lists the valid ones; unknown or malformed parameters are errors naming the
// field.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/materials/bsdf.h"

namespace weft {

// What a factory may need beyond its parameters: where relative table paths resolve, and the
// name of the file the parameters came from (for error messages). Tables are shared between
// instances and loaded once through 'cache'.
struct MaterialContext {
  std::filesystem::path base_dir = ".";
  std::string source_file;                   // for error messages
  std::string field_prefix;                  // e.g. "materials.seat" for error messages
  std::shared_ptr<struct TableCache> cache;  // may be null: then nothing is shared
  // Where fiber tables baked on demand (fiber_table with "spec") are kept; empty: base_dir /
  // ".weft-cache". And the progress of such bakes (the library never prints).
  std::filesystem::path bake_cache_dir;
  ProgressCallback progress = no_progress();
};

// Builds a BSDF of the named type from its JSON parameters.
Bsdf make_bsdf(const std::string& type, const nlohmann::json& params, const MaterialContext& ctx);

// The names make_bsdf accepts, in a stable order.
std::vector<std::string> material_names();

}  // namespace weft
