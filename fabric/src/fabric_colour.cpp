#include "weft/fabric/fabric_colour.h"

#include <fstream>

#include "weft/core/atomic_file.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/fiber/thread_colour.h"
#include "weft/materials/colour_reading.h"

namespace weft {

namespace {

// Bumped when a reading would change for the same inputs (stale cache entries are then unused).
constexpr int kColourCacheVersion = 2;
const std::filesystem::path kColourCacheDir = ".weft-cache";

FiberTableBakeOptions reading_fiber_options(const FiberSpec& spec, const FabricBakePlan& p) {
  FiberTableBakeOptions o = fiber_bake_defaults(spec);
  o.spectral = true;  // the reading is a spectrum
  o.resolution = p.request.resolution;
  return o;
}

// What a reading depends on besides the fiber: the sample, the method and its settings.
nlohmann::json reading_inputs(const FabricBakePlan& p, const WovenSample& sample) {
  const FabricRaytraceOptions& r = p.raytrace;
  return {{"version", kColourCacheVersion},
          {"sample", woven_sample_identity(sample)},
          {"method", p.request.method},
          {"resolution", p.request.resolution},
          {"samples", p.request.samples ? nlohmann::json(*p.request.samples) : nullptr},
          {"seed", p.request.seed},
          {"raytrace",
           {r.particles_per_bin, r.max_scatterings, r.roulette_threshold, r.split_threshold,
            static_cast<int>(r.channel_sampling), static_cast<int>(r.straight_through),
            r.next_event_rays, r.launch_lattice}}};
}

std::filesystem::path colour_cache_file(const nlohmann::json& inputs, const FiberSpec& base,
                                        const ColourTarget& target) {
  const std::string key = fiber_spec_hash_hex(base) + target.key() + inputs.dump();
  return kColourCacheDir / ("colour-" + hex64(fnv1a64(key)) + ".json");
}

nlohmann::json readings_json(const ColourMatch& m) {
  nlohmann::json list = nlohmann::json::array();
  for (const ColourReading& r : m.readings)
    list.push_back(
        {{"scale", r.scale}, {"reflectance", r.reflectance}, {"cpu_seconds", r.cpu_seconds}});
  return list;
}

// A cached match: its readings replayed through the solver (no reading is taken again).
std::optional<ColourMatch> cached_match(const std::filesystem::path& file, const FiberSpec& base,
                                        const ColourTarget& target) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    const nlohmann::json& readings = j.at("readings");
    size_t next = 0;
    bool replayed_all = true;
    ColourMatch m = match_colour(base, target,
                                 [&](const FiberSpec&) -> std::optional<Spectrum> {
                                   if (next >= readings.size())
                                     return replayed_all = false, std::nullopt;
                                   return readings[next++].at("reflectance").get<Spectrum>();
                                 },
                                 {});
    if (!replayed_all || next != readings.size()) return std::nullopt;
    for (size_t k = 0; k < m.readings.size(); ++k) {
      // The solver asked for the scales the entry's readings were taken at, or it is stale.
      if (m.readings[k].scale != readings[k].at("scale").get<std::vector<double>>())
        return std::nullopt;
      m.readings[k].cpu_seconds = readings[k].at("cpu_seconds").get<double>();
    }
    return m;
  } catch (const std::exception&) {
    return std::nullopt;  // an unreadable entry is solved again and replaced
  }
}

}  // namespace

nlohmann::json woven_sample_identity(const WovenSample& sample) {
  nlohmann::json woven = nlohmann::json::parse(weave_summary_json(sample.summary, ""));
  woven.erase("seconds");  // how long it took to make, not what it is
  return woven;
}

TabulatedBsdfTable colour_fiber_table(const FabricBakePlan& p, const FiberSpec& spec,
                                      const ProgressCallback& progress) {
  // Interrupted, the bake throws (nothing written); the command reports it as any bake's.
  return TabulatedBsdfTable::read_exr(
      cached_fiber_table(kColourCacheDir, spec, reading_fiber_options(spec, p), progress));
}

std::optional<Spectrum> raytrace_d8_reading(const WovenSample& sample,
                                            const TabulatedBsdfTable& fiber,
                                            FabricRaytraceOptions r,
                                            const ProgressCallback& progress) {
  const int normal_bin = fiber.grid().bin_of({0, 0, 1});
  r.first_bin = normal_bin;
  r.bin_count = 1;
  r.weave_positions_u = r.weave_positions_v = 0;
  const FabricRaytraceResult res = raytrace_fabric_table(sample, fiber, r, progress);
  if (res.cancelled) return std::nullopt;
  const auto albedo = res.table.directional_albedo(normal_bin);
  Spectrum out{};
  for (int b = 0; b < kNumBands; ++b) out[b] = albedo.reflectance[b];
  return out;
}

std::optional<Spectrum> fabric_d8_reading(const FabricBakePlan& p, const WovenSample& sample,
                                          const FiberSpec& spec, const ProgressCallback& progress) {
  const TabulatedBsdfTable fiber = colour_fiber_table(p, spec, progress);
  if (p.method == FabricMethod::kRaytrace)
    return raytrace_d8_reading(sample, fiber, p.raytrace, progress);
  const std::optional<TabulatedBsdfTable> table = summed_fabric_table(p, sample, fiber, progress);
  if (!table) return std::nullopt;
  const auto albedo = table->directional_albedo(fiber.grid().bin_of({0, 0, 1}));
  Spectrum out{};
  for (int b = 0; b < kNumBands; ++b) out[b] = albedo.reflectance[b];
  return out;
}

FabricColourMatch cached_colour_match(const nlohmann::json& inputs, const FiberSpec& base,
                                      const ColourTarget& target,
                                      const ColourReadingFunction& read) {
  const std::filesystem::path file = colour_cache_file(inputs, base, target);
  if (std::optional<ColourMatch> m = cached_match(file, base, target)) return {std::move(*m), true};
  ColourMatchOptions o;
  o.max_readings = kFabricColourReadings;
  ColourMatch m = match_colour(base, target, read, o);
  if (!m.cancelled) {
    std::filesystem::create_directories(kColourCacheDir);
    const nlohmann::json entry = {{"inputs", inputs},
                                  {"fiber_spec_hash", fiber_spec_hash_hex(base)},
                                  {"target", target.spec},
                                  {"readings", readings_json(m)}};
    write_atomically(file, [&](const std::filesystem::path& tmp) {
      std::ofstream(tmp) << entry.dump(1) << "\n";
    });
  }
  return {std::move(m), false};
}

FabricColourMatch match_fabric_colour(const FabricBakePlan& p, const WovenSample& sample,
                                      const ProgressCallback& progress) {
  return cached_colour_match(
      reading_inputs(p, sample), load_fiber_spec(p.request.fiber), p.colour.value(),
      [&](const FiberSpec& spec) { return fabric_d8_reading(p, sample, spec, progress); });
}

std::optional<std::vector<FiberSpec>> match_thread_colours(const FabricBakePlan& p,
                                                           const WovenSample& sample,
                                                           const ProgressCallback& progress,
                                                           nlohmann::json& summary) {
  std::vector<std::array<double, 3>> colours;
  fiber_tables_by_colour(sample, colours, "--thread-colours");
  const FiberSpec base = load_fiber_spec(p.request.fiber);
  const nlohmann::json inputs = reading_inputs(p, sample);
  std::vector<FiberSpec> specs;
  summary = nlohmann::json::array();
  for (const auto& c : colours) {
    const std::string hex = srgb_hex(c);
    // White reads the cloth's own paleness, which no absorber raises: the undyed fibre.
    if (c == std::array<double, 3>{1, 1, 1}) {
      specs.push_back(base);
      summary.push_back({{"colour", hex}, {"note", "white: the undyed fiber"}});
      continue;
    }
    const FabricColourMatch m = cached_colour_match(
        inputs, base, read_colour_target("srgb:" + hex, "--thread-colours"),
        [&](const FiberSpec& s) { return fabric_d8_reading(p, sample, s, progress); });
    if (m.match.cancelled) return std::nullopt;
    nlohmann::json j = colour_match_summary(m.match);
    j["colour"] = hex;
    j["cached"] = m.cached;
    j["note"] = colour_match_note(m);
    summary.push_back(j);
    specs.push_back(m.match.spec);
    specs.back().name = base.name + " " + hex;  // as the rule names it: the thread's colour
  }
  return specs;
}

void check_thread_colour_match(const FabricBakeRequest& o, size_t colours) {
  const char* option = "--thread-colour-method";
  const FiberSpec spec = load_fiber_spec(o.fiber);
  if (!spec.dyes.empty())
    throw Error(o.fiber, option,
                "match solves the thread-colour absorbers of an undyed --fiber; '" + spec.name +
                    "' has dyes of its own, which the match would fight: give the undyed fiber "
                    "(such as white-cotton), or --thread-colour-method rule");
  FiberTableBakeOptions bake = reading_fiber_options(spec, FabricBakePlan{.request = o});
  bake.photons_per_band *= kFabricColourReadings * colours;
  check_fiber_bake(o.limits, bake, kNumBands, {o.fiber, option, option});
  check_fabric_bake(o.limits, FabricMethod::kRaytrace, o.resolution,
                    kFabricColourReadings * static_cast<int>(colours), o.samples, o.threads,
                    option);
}

ColourTarget check_fabric_colour(const FabricBakeRequest& o, FabricMethod method) {
  const ColourTarget target = read_colour_target(o.colour, "--colour");
  if (o.fiber_table || is_fiber_table_file(o.fiber))
    throw Error(o.fiber, "--colour",
                "--colour sets the depth of a fiber spec's dyes; a baked fiber table's colour is "
                "fixed: give the spec or preset it was baked from");
  if (o.thread_colours || !o.warp_fiber.empty() || !o.weft_fiber.empty())
    throw Error("", "--colour",
                "--colour dyes the one --fiber; per-yarn fibers (--warp-fiber, --weft-fiber, "
                "--thread-colours) are not matched");
  const FiberSpec spec = load_fiber_spec(o.fiber);
  dye_basis(spec);  // the recipe's dyes exist (the spec's own check) and can be scaled
  // The readings' time: a spectral fiber bake and, for a ray trace, one incident bin each.
  FiberTableBakeOptions bake = reading_fiber_options(spec, FabricBakePlan{.request = o});
  bake.photons_per_band *= kFabricColourReadings;
  check_fiber_bake(o.limits, bake, kNumBands, {o.fiber, "--colour", "--colour"});
  if (method == FabricMethod::kRaytrace)
    check_fabric_bake(o.limits, method, o.resolution, kFabricColourReadings, o.samples, o.threads,
                      "--colour");
  return target;
}

}  // namespace weft

namespace weft {

Lab table_d8_lab(const TabulatedBsdfTable& table, const ColourTarget& target) {
  const auto a = table.directional_albedo(table.grid().bin_of({0, 0, 1}));
  if (table.channels == kNumBands) {
    Spectrum r{};
    for (int b = 0; b < kNumBands; ++b) r[b] = a.reflectance[b];
    return target.lab_of(r);
  }
  return linear_srgb_to_lab({a.reflectance[0], a.reflectance[1], a.reflectance[2]});
}

nlohmann::json colour_summary(const FabricColourMatch& c, const TabulatedBsdfTable& table) {
  nlohmann::json j = colour_match_summary(c.match);
  j["cached"] = c.cached;
  const Lab lab = table_d8_lab(table, c.match.target);
  j["table"] = {{"lab", {lab.l, lab.a, lab.b}},
                {"delta_e00", delta_e00(c.match.target.lab, lab)},
                {"channels", table.channels == kNumBands ? "spectral" : "rgb"}};
  return j;
}

std::string colour_metadata(const FabricColourMatch& c) {
  char de[32];
  std::snprintf(de, sizeof de, "%.2f", c.match.best_reading().delta_e00);
  return c.match.target.spec + " (CIEDE2000 " + de + " at normal incidence)";
}

std::string colour_match_note(const FabricColourMatch& c) {
  const ColourMatch& m = c.match;
  const ColourReading& best = m.best_reading();
  char de[32];
  std::snprintf(de, sizeof de, "%.2f", best.delta_e00);
  std::string scales;
  for (size_t d = 0; d < m.basis.names.size(); ++d) {
    char v[64];
    std::snprintf(v, sizeof v, "%s%s %.4g%s", d ? ", " : "", m.basis.names[d].c_str(),
                  best.scale[d], m.basis.recipe ? " % owf" : "");
    scales += v;
  }
  const std::string how =
      c.cached ? "from the cache" : std::to_string(m.readings.size()) + " readings";
  if (m.reached)
    return "colour " + m.target.spec + " reached: CIEDE2000 " + de + " (" + how + "); " + scales;
  return "colour " + m.target.spec +
         (m.outside_reach ? " is outside what the dyes can reach" : " not reached") + ": nearest " +
         format_lab(best.lab) + " at CIEDE2000 " + de + " (" + how + "); " + scales;
}

void describe_colour_match(const FabricColourMatch& c, TabulatedBsdfTable& table,
                           FabricBakeResult& out) {
  table.metadata["colour"] = colour_metadata(c);
  out.notes.push_back(colour_match_note(c));
}

}  // namespace weft
