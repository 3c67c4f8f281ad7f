#include "weft/fabric/fabric_fibers.h"

#include <algorithm>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/thread_colour.h"
#include "weft/scenes/wif.h"

namespace weft {

bool is_fiber_table_file(const std::string& fiber) {
  std::error_code ec;
  return std::filesystem::path(fiber).extension() == ".exr" ||
         (std::filesystem::is_regular_file(fiber, ec) && fiber.size() > 4 &&
          fiber.compare(fiber.size() - 4, 4, ".exr") == 0);
}

namespace {

// The draft states colours, at most kMaxThreadColours distinct ones, and --fiber is a spec.
void check_draft_colours(const FabricFiberOptions& o) {
  const WifDraft draft = read_wif(o.draft);
  if (!draft.colours_given)
    throw Error(o.draft, "WARP COLORS",
                "the draft states no thread colour ([WARP]/[WEFT] Color, [WARP COLORS], "
                "[WEFT COLORS]): --thread-colours has nothing to dye");
  const size_t distinct = thread_colour_count(o.draft);
  if (distinct > static_cast<size_t>(kMaxThreadColours))
    throw Error(o.draft, "WARP COLORS",
                "the threads have " + std::to_string(distinct) +
                    " distinct colours ([WARP COLORS], [WEFT COLORS]); --thread-colours takes at "
                    "most " +
                    std::to_string(kMaxThreadColours) + ", a fiber table baked for each");
  if (o.fiber_table || is_fiber_table_file(o.fiber))
    throw Error("", "--fiber",
                "--thread-colours dyes a fiber spec or preset (its host absorption), not a "
                "table: give a spec or preset such as white-cotton");
}

// One table per distinct colour of the draft's threads, each --fiber dyed by the colour's rule.
FabricFibers colour_fibers(const FabricFiberOptions& o, const WovenSample& sample,
                           const ProgressCallback& progress) {
  std::vector<std::array<double, 3>> colours;
  FabricFibers f;
  f.map = fiber_tables_by_colour(sample, colours, "--thread-colours");
  const FiberSpec base = load_fiber_spec(o.fiber);
  for (size_t k = 0; k < colours.size(); ++k) {
    const std::string name = srgb_hex(colours[k]);
    const std::string option = "--thread-colours " + name;
    const FiberSpec spec = o.thread_specs.empty() ? thread_colour_spec(base, colours[k], option)
                                                  : o.thread_specs.at(k);
    f.held.push_back(cached_fabric_fiber(spec, option, option, o.limits, progress));
    f.map.tables[k] = &f.held.back();
    f.map.names.push_back(name);
  }
  return f;
}

}  // namespace

size_t thread_colour_count(const std::string& draft_file) {
  const WifDraft draft = read_wif(draft_file);
  std::vector<std::array<double, 3>> distinct;
  for (const auto* threads : {&draft.warp, &draft.weft})
    for (const WifThread& t : *threads)
      if (std::find(distinct.begin(), distinct.end(), t.rgb) == distinct.end())
        distinct.push_back(t.rgb);
  return distinct.size();
}

FiberTableBakeOptions fabric_fiber_bake_options(const FiberSpec& spec) {
  FiberTableBakeOptions o = fiber_bake_defaults(spec);
  // A dye's absorption is a spectrum: its RGB table leaves the sRGB gamut (the bundled red
  // cotton's has linear-sRGB values down to -0.46, clipped, and a paler congo red a channel
  // albedo of 1.12, which the ray trace refuses), so a dyed fiber is traced by band. An undyed or
  // thread-coloured one (smooth absorbers) stays RGB, a third of the memory.
  o.spectral = !spec.dyes.empty();
  return o;
}

TabulatedBsdfTable cached_fabric_fiber(const FiberSpec& spec, const std::string& source,
                                       const std::string& option, const RunLimits& limits,
                                       const ProgressCallback& progress) {
  const FiberTableBakeOptions o = fabric_fiber_bake_options(spec);
  return TabulatedBsdfTable::read_exr(
      cached_fiber_table(".weft-cache", spec, o, progress, nullptr, [&] {
        check_fiber_bake(limits, o, kNumBands, {source, option, option});
      }));
}

TabulatedBsdfTable named_fiber_table(const std::string& fiber, const std::string& option,
                                     const RunLimits& limits, const ProgressCallback& progress) {
  if (is_fiber_table_file(fiber)) return TabulatedBsdfTable::read_exr(fiber);
  return cached_fabric_fiber(load_fiber_spec(fiber), fiber, option, limits, progress);
}

bool per_yarn_fibers(const FabricFiberOptions& o) {
  const std::string& warp = o.warp_fiber.empty() ? o.fiber : o.warp_fiber;
  const std::string& weft = o.weft_fiber.empty() ? o.fiber : o.weft_fiber;
  return o.thread_colours || warp != weft;
}

void check_fabric_fiber_options(const FabricFiberOptions& o, bool raytrace) {
  if (o.thread_colours && (!o.warp_fiber.empty() || !o.weft_fiber.empty()))
    throw Error("", "--thread-colours",
                "give either --thread-colours or --warp-fiber/--weft-fiber, not both");
  if (o.thread_colours && o.draft.empty())
    throw Error("", "--thread-colours", "needs a WIF draft: --wif, or a --weave file naming one");
  if (o.thread_colours) check_draft_colours(o);
  if (!per_yarn_fibers(o)) return;
  const std::string option = o.thread_colours        ? "--thread-colours"
                             : !o.warp_fiber.empty() ? "--warp-fiber"
                                                     : "--weft-fiber";
  if (!raytrace)
    throw Error("", option,
                "the summations take one fiber for the whole cloth; per-yarn fibers need "
                "--method raytrace");
}

namespace {

// One yarn's table: --fiber's own where the caller holds it, else loaded or baked.
const TabulatedBsdfTable& yarn_fiber_table(const FabricFiberOptions& o, FabricFibers& f,
                                           const std::string& name, const std::string& option,
                                           const ProgressCallback& progress) {
  if (o.fiber_table && option == "--fiber") return *(f.given = o.fiber_table);
  return f.held.emplace_back(named_fiber_table(name, option, o.limits, progress));
}

}  // namespace

FabricFibers load_fabric_fibers(const FabricFiberOptions& o, const WovenSample& sample,
                                const ProgressCallback& progress) {
  if (o.thread_colours) return colour_fibers(o, sample, progress);
  FabricFibers f;
  if (!per_yarn_fibers(o)) {
    const std::string& only = o.warp_fiber.empty() ? o.fiber : o.warp_fiber;
    f.map.tables = {
        &yarn_fiber_table(o, f, only, only == o.fiber ? "--fiber" : "--warp-fiber", progress)};
    return f;
  }
  const TabulatedBsdfTable& warp =
      yarn_fiber_table(o, f, o.warp_fiber.empty() ? o.fiber : o.warp_fiber,
                       o.warp_fiber.empty() ? "--fiber" : "--warp-fiber", progress);
  const TabulatedBsdfTable& weft =
      yarn_fiber_table(o, f, o.weft_fiber.empty() ? o.fiber : o.weft_fiber,
                       o.weft_fiber.empty() ? "--fiber" : "--weft-fiber", progress);
  f.map = fiber_tables_by_direction(sample, warp, weft);
  return f;
}

nlohmann::json FabricFibers::summary() const {
  nlohmann::json list = nlohmann::json::array();
  for (size_t k = 0; k < map.tables.size(); ++k) {
    const TabulatedBsdfTable& t = *map.tables[k];
    const auto spec = t.metadata.find("spec_name");
    list.push_back({{"name", k < map.names.size() ? map.names[k] : ""},
                    {"checksum", t.checksum()},
                    {"spec", spec == t.metadata.end() ? "" : spec->second}});
  }
  return list;
}

}  // namespace weft
