#pragma once
// Materials by name: one explicit name -> factory table (no static self-registration). The error
// for an unknown name lists the valid ones; unknown, unused or malformed parameters are errors
// naming the field's JSON path. Parameters are read with the one ParamReader (core/params.h).
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/core/params.h"
#include "weft/core/progress.h"
#include "weft/materials/bsdfs.h"

namespace weft {

struct MaterialContext;

// Turns a fiber_table given by a fiber spec ("spec" and its bake settings) into a table file,
// baking it on first use. The registry only reads tables; whoever builds scenes supplies this
// (the fabric library's bake cache, fabric/bake_cache.h), so baking lives in one place above
// both. It reads the keys it owns from 'params' and returns an absolute path or one relative to
// the working directory (never to ctx.base_dir).
using FiberTableResolver =
    std::function<std::filesystem::path(ParamReader& params, const MaterialContext& ctx)>;

// What a factory may need beyond its parameters: where relative table paths resolve, and the
// name of the file the parameters came from (for error messages). Tables are shared between
// instances and loaded once through 'cache'.
struct MaterialContext {
  std::filesystem::path base_dir = ".";
  std::string source_file;   // for error messages
  std::string field_prefix;  // JSON path of the parameters, e.g. "materials.seat.params"
  std::shared_ptr<struct TableCache> cache;  // may be null: then nothing is shared
  FiberTableResolver fiber_tables;           // may be null: then "spec" is an error
  ProgressCallback progress =
      no_progress();  // of work the resolver does (the library never prints)
};

// Builds a BSDF of the named type from its JSON parameters.
Bsdf make_bsdf(const std::string& type, const nlohmann::json& params, const MaterialContext& ctx);

// The names make_bsdf accepts, in a stable order.
std::vector<std::string> material_names();

}  // namespace weft
