#pragma once
// The fiber tables of a fabric bake (fabric_bake.h): the one --fiber, or one per yarn: --warp-fiber
// and --weft-fiber, or a WIF draft's --thread-colours, each colour a dye of --fiber
// (fiber/thread_colour.h; docs/fabric-bsdf.md "Per-yarn fibers").
#include <deque>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft {

// How --thread-colours dyes --fiber to a thread's colour (docs/fabric-bsdf.md "Thread colours").
enum class ThreadColourMethod { kMatch, kRule };
inline constexpr NameTable<ThreadColourMethod, 2> kThreadColourMethods{{
    {ThreadColourMethod::kMatch, "match",
     "each colour's absorbers solved so that a cloth of that thread alone reads the colour "
     "(fabric_colour.h)"},
    {ThreadColourMethod::kRule, "rule",
     "the colour's smooth uplift, one pass across the fibre (fiber/thread_colour.h: no readings; "
     "the cloth comes out darker and more saturated than the swatch)"},
}};

struct FabricFiberOptions {
  std::string fiber, warp_fiber, weft_fiber;  // warp/weft: "" = --fiber
  // --fiber's table when the caller holds it already (Python's Table): 'fiber' then only names it.
  std::shared_ptr<const TabulatedBsdfTable> fiber_table;
  bool thread_colours = false;
  ThreadColourMethod thread_colour_method = ThreadColourMethod::kMatch;
  // --thread-colours match: the matched spec of each distinct colour of the draft (in
  // fiber_tables_by_colour's order; the run fills it in before loading the tables); empty: the
  // rule's.
  std::vector<FiberSpec> thread_specs;
  std::string draft;  // the WIF draft (--wif, or the one --weave names); "" when none
  RunLimits limits;   // a bake on first use is checked under these
};

// The most distinct thread colours --thread-colours takes (a fiber table baked for each).
inline constexpr int kMaxThreadColours = 8;

// Checked before any work: the options that need a ray trace, a draft, or exclude each other
// (weft::Error naming the option). 'raytrace': --method raytrace.
void check_fabric_fiber_options(const FabricFiberOptions& o, bool raytrace);
// The distinct thread colours of a draft (at most kMaxThreadColours, checked above).
size_t thread_colour_count(const std::string& draft);
// True when the run traces more than one fiber (per-yarn tables may still turn out equal).
bool per_yarn_fibers(const FabricFiberOptions& o);

// The tables, loaded or baked on first use into ./.weft-cache, held for the run; 'map' is what
// the ray trace takes (one table, every yarn on it, without per-yarn options).
struct FabricFibers {
  std::deque<TabulatedBsdfTable> held;
  std::shared_ptr<const TabulatedBsdfTable> given;  // FabricFiberOptions::fiber_table
  FiberTables map;
  const TabulatedBsdfTable& first() const { return *map.tables.at(0); }
  // Per table: its name, checksum and spec name (for --json).
  nlohmann::json summary() const;
};
FabricFibers load_fabric_fibers(const FabricFiberOptions& o, const WovenSample& sample,
                                const ProgressCallback& progress);

// Whether --fiber names a fiber table file (.exr) rather than a spec or preset.
bool is_fiber_table_file(const std::string& fiber);
// How a fabric bakes the fiber table of a spec: at the bake's defaults, spectral (33 bands) for a
// dyed spec, whose colour an RGB table cannot hold without clipping, else RGB.
FiberTableBakeOptions fabric_fiber_bake_options(const FiberSpec& spec);
// That table, baked once into ./.weft-cache; 'source' and 'option' name it in the bake's checks.
TabulatedBsdfTable cached_fabric_fiber(const FiberSpec& spec, const std::string& source,
                                       const std::string& option, const RunLimits& limits,
                                       const ProgressCallback& progress);

// One fiber table: a table file (.exr), or a fiber spec or preset baked once into ./.weft-cache
// (cached_fabric_fiber); 'option' names it in the bake's checks.
TabulatedBsdfTable named_fiber_table(const std::string& fiber, const std::string& option,
                                     const RunLimits& limits, const ProgressCallback& progress);

}  // namespace weft
