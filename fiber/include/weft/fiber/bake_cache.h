#pragma once
// Fiber tables baked on first use ("model only what a scene requires"). A scene's fiber_table may
// name a fiber spec instead of a baked file; the bake cache turns it into a table file, baking it
// once and keeping it under a key of everything that determines its bits (spec physics,
// resolution, photons, seed, passes, format), so every later render reuses it.
#include <filesystem>
#include <functional>
#include <string>

#include "weft/core/run_limits.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/materials/registry.h"

namespace weft {

// The cache file for a spec and bake options in 'dir' (RGB tables, as scenes use them).
std::filesystem::path fiber_table_cache_file(const std::filesystem::path& dir,
                                             const FiberSpec& spec,
                                             const FiberTableBakeOptions& options);

// The table for (spec, options) in 'dir': read from the cache when present and whole, else baked
// (progress through 'progress') and written atomically; a damaged entry is baked again. Safe when
// several processes need the same entry at once: one bakes (under an exclusive lock on the
// entry's ".lock" file, which the system releases if the process dies), the others wait and reuse
// its result. 'baked' (may be null) says whether this call baked. 'before_bake' (may be empty) is
// called when the table must be baked, before anything is written (the cache folder included):
// a front end's estimate of the bake, which throws to refuse it. Error when interrupted (nothing
// is written).
std::filesystem::path cached_fiber_table(const std::filesystem::path& dir, const FiberSpec& spec,
                                         const FiberTableBakeOptions& options,
                                         const ProgressCallback& progress, bool* baked = nullptr,
                                         const std::function<void()>& before_bake = {});

// The fiber's volume albedo per band (exit minus surface fraction, FiberBandResult), which a table
// does not hold but a cache entry records in its metadata "volume_albedo" (33 numbers, round-trip
// precision): what the classic model of weft verify takes as its colour. volume_albedo_metadata
// writes it, volume_albedo_of reads it (weft::Error naming 'file' when missing or malformed).
std::string volume_albedo_metadata(const FiberTableBakeResult& result);
Spectrum volume_albedo_of(const TabulatedBsdfTable& table, const std::string& file);

// Where a bake's settings were read, for a refusal: the file and the fields of its photon count
// and resolution.
struct FiberBakeSource {
  std::string file, photons_field, resolution_field;
};
// A front end's check of a bake on first use (its time and memory): throws weft::Error to refuse.
using FiberBakeCheck = std::function<void(const FiberTableBakeOptions&, const FiberBakeSource&)>;

// The material registry's FiberTableResolver: reads "spec" (a spec file relative to the scene's
// folder, or a preset name) and the optional bake settings "resolution", "photons", "seed"
// (defaults: FiberTableBakeOptions), and returns the cached table. 'cache_dir' empty: a
// ".weft-cache" folder next to the scene description. 'check' (may be empty) runs before a bake,
// not when the table is cached; its error propagates as it is.
FiberTableResolver fiber_table_resolver(std::filesystem::path cache_dir = {},
                                        FiberBakeCheck check = {});

// The checks before a fiber bake, the same for `weft bake fiber`, a bake on first use and Python:
// its memory (check_memory, fiber_table_bake_bytes) and its time for 'bands' bands
// (check_long_work at fiber_bake_min_seconds_per_photon), naming the source's file and fields.
void check_fiber_bake(const RunLimits& limits, const FiberTableBakeOptions& options, uint64_t bands,
                      const FiberBakeSource& source);
// The fiber-table resolver of every command that renders a scene: fiber_table_resolver (bake on
// first use) with check_fiber_bake under 'limits' before a bake.
FiberTableResolver checked_fiber_table_resolver(const RunLimits& limits);

}  // namespace weft
