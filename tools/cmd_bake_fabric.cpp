// weft bake fabric: a fiber table (file, or a spec baked on demand) and a woven sample -> a fabric
// BSDF table, by the paper's summation, our visible-layer summation or the ray-traced reference.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "bake_fabric_fibers.h"
#include "commands.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fabric/weave_tally.h"
#include "weft/fiber/bake_cache.h"
#include "weft/scenes/weave.h"

namespace weft::cli {
namespace {

// The summations' direction pairs per cell pair at most (fabric_summation.cpp checks the same).
constexpr uint64_t kMaxSummationSamples = 4096;
// --estimator nee's draws per scattering unless --next-event-rays is given (docs/PERFORMANCE.md).
constexpr int kDefaultNextEventRays = 1, kDefaultLaunchLattice = 13;
// The weave table's position cells per side and coarse R unless given (docs/fabric-bsdf.md, "The
// weave table": its noise and cost on the bundled poplin).
constexpr int kDefaultWeavePositions = 8, kDefaultWeaveResolution = 4;

struct BakeFabricOptions {
  std::string fiber = "red-cotton", method = "summation", output, weave, pattern, wif;
  std::string warp_fiber, weft_fiber;             // per-yarn fibers (raytrace); "" = --fiber
  bool thread_colours = false;                    // a fiber per colour of the WIF draft's threads
  std::string detail = "yarn", shard, estimator;  // estimator: "" = hero
  std::string straight_through;                   // "" = the library's default
  int resolution = 8, threads = 0;
  std::optional<uint64_t> samples;  // the method's default unless given
  uint64_t seed = 1;
  std::optional<double> split_threshold;  // the library's default unless given
  std::optional<int> max_scatterings;     // the library's default unless given
  std::optional<int> next_event_rays;     // --estimator nee: kDefaultNextEventRays unless given
  std::optional<int> launch_lattice;      // --estimator nee: kDefaultLaunchLattice unless given
  std::string weave_out;                  // the weave table (.exr); "" = no weave tally
  std::optional<std::string> weave_positions;  // "N" or "UxV"
  std::optional<int> weave_resolution;         // kDefaultWeaveResolution (at most R) unless given
  bool json = false, quiet = false, resume = false;
};

WeaveOptions weave_options(const BakeFabricOptions& o) {
  WeaveOptions given;
  if (!o.pattern.empty()) given.pattern = o.pattern;
  if (!o.wif.empty()) given.wif = o.wif;
  if (!o.pattern.empty() && !o.wif.empty())
    throw Error("", "wif", "give either --pattern or --wif, not both");
  given.detail = o.detail;
  const WeaveOptions base = o.weave.empty() ? WeaveOptions{} : read_weave_options(o.weave);
  return overlay(base, given);
}

// Coarser yarn tessellations (sides = segments per crossing) tried, finest first, where the
// default one would not fit.
constexpr int kFittingTessellations[] = {12, 8, 6, 4};

// The memory of the scene a ray trace or summation-visible builds (fabric_scene_bytes), estimated
// from the sample's options before anything is built and checked against the budget (check_memory)
// naming the draft. Yarn tubes whose tessellation (sides, segments per crossing) was left at its
// default take the finest coarser one that fits instead, said in 'note', unless the run is one
// piece of a job ('may_coarsen' false: every piece must trace the same sample, whatever memory
// its machine has); 'bytes' gets the estimate.
WeaveOptions fitted_weave_options(const RunLimits& limits, WeaveOptions w, const std::string& draft,
                                  bool may_coarsen, std::string* note, double* bytes) {
  WovenSampleSize z = woven_sample_size(w);
  const double budget = memory_budget_bytes(limits);
  if (may_coarsen && z.detail == "yarn" && !w.sides && !w.segments_per_crossing && budget > 0 &&
      fabric_scene_bytes(z) > budget)
    for (const int n : kFittingTessellations) {
      WeaveOptions c = w;
      c.sides = c.segments_per_crossing = n;
      const WovenSampleSize cz = woven_sample_size(c);
      if (fabric_scene_bytes(cz) > budget && n != kFittingTessellations[3]) continue;
      *note = "yarn tubes of " + std::to_string(z.sides) + " sides and " +
              std::to_string(z.segments_per_crossing) + " segments per crossing would need about " +
              format_bytes(fabric_scene_bytes(z)) + ", more than the memory budget of " +
              format_bytes(budget) + "; traced with " + std::to_string(n) + " and " +
              std::to_string(n) + " (about " + format_bytes(fabric_scene_bytes(cz)) +
              "); give \"sides\" and \"segments-per-crossing\" in --weave to choose";
      w = c, z = cz;
      break;
    }
  const bool yarn = z.detail == "yarn";
  *bytes = fabric_scene_bytes(z);
  check_memory(limits, *bytes, draft, "--detail",
               "the scene at " + z.detail + " detail (" +
                   ParamReader::fmt(yarn ? z.triangles : z.curve_points) +
                   (yarn ? " triangles" : " curve points") + ")");
  return w;
}

// The sample's options, its scene's memory checked (fitted_weave_options) where the method builds
// one: the summations of the paper's method need only the sample's name. 'draft_in_weave': the
// WIF draft the --weave file names.
WeaveOptions sample_options(const RunLimits& limits, const BakeFabricOptions& o,
                            const std::string& draft_in_weave, std::string* note, double* bytes) {
  if (o.method == "summation") return weave_options(o);
  const std::string draft = !o.wif.empty()            ? o.wif
                            : !draft_in_weave.empty() ? draft_in_weave
                                                      : o.weave;
  const WeaveOptions w = fitted_weave_options(limits, weave_options(o), draft,
                                              o.shard.empty() && !o.resume, note, bytes);
  if (!note->empty()) std::fprintf(stderr, "weft: %s\n", note->c_str());
  return w;
}

std::vector<FiberOrientation> orientations(const std::vector<Vec3>& tangents) {
  std::vector<FiberOrientation> out;
  for (const Vec3& t : tangents) out.push_back({t, 1.0});
  return out;
}

// --weave-positions: "N" (N x N cells) or "UxV", each a whole number in [1, kMaxPositions].
std::pair<int, int> weave_positions_of(const std::string& text) {
  auto side = [&](const std::string& part) {
    const std::optional<double> n = finite_number(part);
    if (!n || *n != std::floor(*n) || *n < 1 || *n > WeaveTable::kMaxPositions)
      throw Error("", "--weave-positions",
                  "expected N or UxV, whole numbers in [1, " +
                      std::to_string(WeaveTable::kMaxPositions) + "], got '" + text + "'");
    return static_cast<int>(*n);
  };
  const size_t x = text.find('x');
  if (x == std::string::npos) return {side(text), side(text)};
  return {side(text.substr(0, x)), side(text.substr(x + 1))};
}

// The weave tally's settings (weave_tally.h): on with --weave-out.
void weave_tally_options(const BakeFabricOptions& o, FabricRaytraceOptions& r) {
  if (o.weave_out.empty()) {
    if (o.weave_positions)
      throw Error("", "--weave-positions", "the weave table's positions need --weave-out");
    if (o.weave_resolution)
      throw Error("", "--weave-resolution", "the weave table's resolution needs --weave-out");
    return;
  }
  const auto [u, v] =
      weave_positions_of(o.weave_positions.value_or(std::to_string(kDefaultWeavePositions)));
  r.weave_positions_u = u, r.weave_positions_v = v;
  r.weave_resolution = o.weave_resolution.value_or(std::min(kDefaultWeaveResolution, r.resolution));
  if (r.weave_resolution < 1 || r.weave_resolution > r.resolution)
    throw Error("", "--weave-resolution",
                "must lie in [1, the table's resolution " + std::to_string(r.resolution) +
                    "], got " + std::to_string(r.weave_resolution));
}

// The ray tracer's settings from the command line, checked before any work: options that do
// nothing in the configuration given are errors, and a bad value names its option.
FabricRaytraceOptions raytrace_options(const BakeFabricOptions& o) {
  FabricRaytraceOptions r;
  r.resolution = o.resolution;
  if (o.samples) r.particles_per_bin = *o.samples;
  r.seed = o.seed;
  r.threads = o.threads;
  r.channel_sampling =
      o.estimator == "mean" ? ChannelSampling::mean : ChannelSampling::spectral_mis;
  if (o.next_event_rays && o.estimator != "nee")
    throw Error("", "--next-event-rays",
                "next-event rays are the nee estimator's: give --estimator nee");
  if (o.launch_lattice && o.estimator != "nee")
    throw Error("", "--launch-lattice",
                "launch blocks are the nee estimator's: give --estimator nee");
  if (o.estimator == "nee") {
    r.next_event_rays = o.next_event_rays.value_or(kDefaultNextEventRays);
    r.launch_lattice = o.launch_lattice.value_or(kDefaultLaunchLattice);
  }
  if (!o.straight_through.empty())
    r.straight_through =
        o.straight_through == "sampled" ? StraightThrough::sampled : StraightThrough::exact;
  if (o.split_threshold) {
    if (r.channel_sampling == ChannelSampling::mean)
      throw Error("", "--split-threshold",
                  "the mean estimator does not split: give --estimator hero");
    r.split_threshold = *o.split_threshold;
    if (!std::isfinite(r.split_threshold) || !(r.split_threshold > r.roulette_threshold))
      throw Error("", "--split-threshold",
                  "must be finite and above the roulette threshold " +
                      std::to_string(r.roulette_threshold) + ", got " +
                      std::to_string(r.split_threshold));
  }
  if (o.max_scatterings) r.max_scatterings = *o.max_scatterings;
  weave_tally_options(o, r);
  r.validate();
  return r;
}

// The work's time from a lower bound of its rate, before any (check_fabric_bake): a ray trace's
// incident bins are those of its shard.
void check_fabric_work(const RunLimits& limits, const BakeFabricOptions& o) {
  const uint64_t bins = static_cast<uint64_t>(DirectionGrid{o.resolution}.bins());
  const UnitRange r =
      o.method == "raytrace"
          ? shard_units(bins, o.shard.empty() ? Shard{} : parse_shard(o.shard, "--shard"))
          : UnitRange{0, bins};
  check_fabric_bake(limits, value_of(kFabricMethods, o.method, "", "--method"), o.resolution,
                    r.last - r.first, o.samples, o.threads, "--samples");
}

// The ray tracer's options given to a summation, and a summation's sample count, refused.
void check_method_options(const BakeFabricOptions& o) {
  if ((!o.shard.empty() || o.resume) && o.method != "raytrace")
    throw Error("", "--shard", "--shard and --resume need --method raytrace");
  if (o.method != "raytrace" && !o.estimator.empty())
    throw Error("", "--estimator", "the estimator is the ray tracer's: it needs --method raytrace");
  // Checked before narrowing to the summation's int: 2^32 + 1 wrapped to 1.
  if (o.method != "raytrace" && o.samples && *o.samples > kMaxSummationSamples)
    throw Error("", "--samples",
                "a summation takes 1 to " + std::to_string(kMaxSummationSamples) +
                    " direction pairs per cell pair, got " + std::to_string(*o.samples));
  if (o.method != "raytrace" && !o.straight_through.empty())
    throw Error("", "--straight-through", "the ray tracer's: it needs --method raytrace");
  if (o.method != "raytrace" && o.max_scatterings)
    throw Error("", "--max-scatterings", "the ray tracer's: it needs --method raytrace");
  if (o.method != "raytrace" && o.split_threshold)
    throw Error("", "--split-threshold",
                "splitting is the ray tracer's: it needs --method raytrace");
  if (o.method != "raytrace" && (!o.weave_out.empty() || o.weave_positions || o.weave_resolution))
    throw Error("", o.weave_out.empty() ? "--weave-positions" : "--weave-out",
                "the weave table is the ray tracer's: it needs --method raytrace");
  if (!o.weave_out.empty() && std::filesystem::path(o.weave_out).extension() != ".exr")
    throw Error(o.weave_out, "--weave-out", "the weave table must be written to a .exr file");
}

// The scene's memory and the weave tally's (weave_tally_bytes) against the budget, once the
// fiber table's channels are known; the tally's bytes (0 without it).
double check_weave_memory(const RunLimits& limits, const FabricRaytraceOptions& r, int channels,
                          double scene_bytes) {
  if (r.weave_positions_u == 0) return 0;
  const double bytes = weave_tally_bytes(r.resolution, r.weave_resolution, r.weave_positions_u,
                                         r.weave_positions_v, channels);
  check_memory(limits, scene_bytes + bytes, "", "--weave-positions",
               "the scene and the weave tally of " + std::to_string(r.weave_positions_u) + "x" +
                   std::to_string(r.weave_positions_v) + " positions at resolution " +
                   std::to_string(r.weave_resolution) + " (" + format_bytes(bytes) + ")");
  return bytes;
}

// What --json says of the weave table, and its line without --json.
nlohmann::json weave_summary(const FabricRaytraceResult& res, const std::string& file) {
  return {{"file", file},
          {"positions",
           std::to_string(res.weave.positions_u) + "x" + std::to_string(res.weave.positions_v)},
          {"resolution", res.weave.resolution},
          {"relative_noise", res.weave_relative_noise}};
}
void print_weave_summary(const nlohmann::json& w) {
  std::printf("%s: weave table, %s positions, resolution %d; relative noise %.4g\n",
              w.at("file").get<std::string>().c_str(), w.at("positions").get<std::string>().c_str(),
              w.at("resolution").get<int>(), w.at("relative_noise").get<double>());
}

// The line without --json of what 1 % noise per channel would cost (noise_cost_summary).
void print_noise_cost(const nlohmann::json& cost, const nlohmann::json& noise) {
  std::printf("relative noise per channel");
  for (const auto& n : noise) std::printf(" %.3g %%", 100 * n.get<double>());
  std::printf("; 1 %% in each would take");
  for (const auto& c : cost.at("cpu_seconds_to_target")) {
    if (c.is_null())
      std::printf(" -");
    else
      std::printf(" %.3g", c.get<double>());
  }
  std::printf(" CPU-s\n");
}

// The weave table of a ray trace with --weave-out, its --json keys added to 'extra'.
WeaveTable take_weave(FabricRaytraceResult& res, const std::string& file, double bytes,
                      nlohmann::json& extra) {
  extra["weave"] = weave_summary(res, file);
  extra["weave"]["memory_estimate_bytes"] = bytes;
  return std::move(res.weave);
}

// Written after the fabric table, its metadata the table's as written.
void write_weave(const TabulatedBsdfTable& table, WeaveTable& weave, const std::string& file) {
  describe_weave(table, weave);
  weave.write_exr(file);
}

// A shard's run ends with its part written ('code' 0), which carries the weave tally.
int part_written(const BakeFabricOptions& o, int code) {
  if (code == 0 && !o.weave_out.empty())
    std::fprintf(stderr,
                 "weft: the part carries the weave tally; `weft merge --weave-out %s` writes the "
                 "weave table\n",
                 o.weave_out.c_str());
  return code;
}

int run(const BakeFabricOptions& o, const RunLimits& program) {
  const RunLimits limits = quieted(program, o.quiet);
  check_method_options(o);
  const FabricRaytraceOptions r =
      o.method == "raytrace" ? raytrace_options(o) : FabricRaytraceOptions{};
  // The WIF draft a weave options file names is read too.
  const std::string weave_wif = o.weave.empty() ? "" : read_weave_options(o.weave).wif.value_or("");
  const FabricFiberOptions fiber_options{
      o.fiber, o.warp_fiber, o.weft_fiber, o.thread_colours, o.wif.empty() ? weave_wif : o.wif,
      limits};
  check_fabric_fiber_options(fiber_options, o.method);
  validate_output_paths(limits,
                        {{o.output, "--output"},
                         {checkpoint_path(o.output), "checkpoint"},
                         {o.weave_out, "--weave-out"}},
                        {{o.fiber, "fiber table or spec"},
                         {o.warp_fiber, "warp fiber table or spec"},
                         {o.weft_fiber, "weft fiber table or spec"},
                         {o.weave, "weave options"},
                         {o.wif, "WIF draft"},
                         {weave_wif, "WIF draft"},
                         {".weft-cache", "fiber-table bake cache"}});
  if (std::filesystem::path(o.output).extension() != ".exr" && o.shard.empty())
    throw Error(o.output, "", "the fabric table must be written to a .exr file");
  check_fabric_work(limits, o);
  std::string note;
  double scene_bytes = 0;
  const WeaveOptions weave = sample_options(limits, o, weave_wif, &note, &scene_bytes);
  const auto progress = progress_bar(limits, o.quiet);
  const WovenSample sample = make_woven_sample(weave);
  const FabricFibers fibers = load_fabric_fibers(fiber_options, sample, progress);
  const TabulatedBsdfTable& fiber = fibers.first();
  const double weave_bytes = check_weave_memory(limits, r, fiber.channels, scene_bytes);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();  // the process's CPU time, all threads
  TabulatedBsdfTable table;
  nlohmann::json extra;
  WeaveTable weave_table;                 // with --weave-out
  std::vector<double> noise_per_channel;  // of a ray trace run whole in this process
  if (o.method == "raytrace") {
    FabricRaytraceResult res;
    if (!o.shard.empty() || o.resume) {
      int code = 0;
      // The files the woven sample was made from (the fiber table is in the job by checksum).
      std::vector<std::filesystem::path> inputs;
      for (const auto& f : {o.weave, o.wif})
        if (!f.empty()) inputs.emplace_back(f);
      auto pieces = raytrace_fabric_in_pieces(sample, input_file_hashes(inputs), fibers.map, r,
                                              o.output, o.shard, o.resume, progress, &code);
      if (!pieces) return part_written(o, code);
      res = std::move(*pieces);
    } else {
      res = fibers.map.tables.size() == 1 ? raytrace_fabric_table(sample, fiber, r, progress)
                                          : raytrace_fabric_table(sample, fibers.map, r, progress);
    }
    if (res.cancelled) {
      std::fprintf(stderr, "\nweft: bake cancelled; nothing was written\n");
      return 130;
    }
    table = res.table;
    record_particle_counts(table, res.splits, res.roulette_kills);
    extra = raytrace_summary(res);
    if (!o.resume) noise_per_channel = res.relative_noise_per_channel;
    if (fibers.map.tables.size() > 1) extra["fiber_tables"] = fibers.summary();
    extra["estimator"] = r.next_event_rays > 0 ? "nee" : channel_sampling_name(r.channel_sampling);
    extra["next_event_rays"] = r.next_event_rays;
    extra["launch_lattice"] = r.launch_lattice;
    extra["straight_through"] = straight_through_name(r.straight_through);
    extra["split_threshold"] = r.channel_sampling == ChannelSampling::mean
                                   ? nlohmann::json(nullptr)
                                   : nlohmann::json(r.split_threshold);
    if (!o.weave_out.empty()) weave_table = take_weave(res, o.weave_out, weave_bytes, extra);
  } else {
    FabricSummationOptions s;
    s.method = o.method == "summation" ? FabricSummation::kPaper : FabricSummation::kVisible;
    s.resolution = o.resolution;
    if (o.samples) s.samples_per_cell = static_cast<int>(*o.samples);  // checked in run()
    s.seed = o.seed;
    s.threads = o.threads;
    if (s.method == FabricSummation::kVisible) {
      s.top = orientations(visible_fiber_tangents(sample, true));
      s.bottom = orientations(visible_fiber_tangents(sample, false));
    }
    table = sum_fabric_table(fiber, s, progress);
  }
  const double seconds = seconds_since(t0);
  table.metadata["sample"] = sample.summary.source + " (" + sample.summary.detail + ")";
  table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
  if (!note.empty()) table.metadata["note"] = note;
  table.write_exr(o.output);
  if (!o.weave_out.empty()) write_weave(table, weave_table, o.weave_out);
  const double cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  nlohmann::json j = {{"output", o.output},
                      {"method", o.method},
                      {"seconds", seconds},
                      {"cpu_seconds", cpu_seconds}};
  j.update(fabric_table_summary(table));
  if (extra.is_object()) j.update(extra);
  // A resumed run's CPU time is of its last part only: its cost of 1 % would be too low.
  if (!noise_per_channel.empty())
    j["noise_cost"] = noise_cost_summary(noise_per_channel, r.particles_per_bin, cpu_seconds);
  if (!note.empty()) j["notes"] = {note};
  if (scene_bytes > 0) j["scene_memory_estimate_bytes"] = scene_bytes;
  if (o.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    auto mean = [](const std::vector<double>& v) {
      double s = 0;
      for (double x : v) s += x;
      return s / static_cast<double>(v.size());
    };
    // Light arriving along the normal, where it goes; and what a view along the normal gathers
    // under uniform light (the renderer's reading). They differ for a non-reciprocal table: the
    // paper's sum transmits nothing downwards but light from below upwards (fabric_summation.h).
    const DirectionGrid g = table.grid();
    const auto normal = table.directional_albedo(g.bin_of({0, 0, 1}));
    const auto view = table.directional_albedo_seen_from(g.bin_of({0, 0, 1}));
    std::printf(
        "%s: %s, R = %d, %.2f s; light along the normal: reflected %.4f, transmitted %.4f; seen "
        "along the normal: reflected %.4f, transmitted %.4f (means over channels)\n",
        o.output.c_str(), o.method.c_str(), o.resolution, seconds, mean(normal.reflectance),
        mean(normal.transmittance), mean(view.reflectance), mean(view.transmittance));
    if (j.contains("noise_cost"))
      print_noise_cost(j["noise_cost"], j["relative_noise_per_channel"]);
    if (extra.contains("weave")) print_weave_summary(extra["weave"]);
  }
  return 0;
}

}  // namespace

void add_bake_fabric_command(CLI::App& bake, Commands& commands) {
  auto o = std::make_shared<BakeFabricOptions>();
  auto* sub =
      bake.add_subcommand("fabric",
                          "Fabric BSDF table from a fiber table and a woven sample (summation, "
                          "summation-visible or the ray-traced reference)");
  sub->add_option("--fiber", o->fiber,
                  "fiber table (.exr), or a fiber spec or preset to bake (with --thread-colours: "
                  "the fiber the colours dye)")
      ->capture_default_str();
  sub->add_option("--warp-fiber", o->warp_fiber,
                  "raytrace: the warp yarns' fiber (table, spec or preset; default --fiber)");
  sub->add_option("--weft-fiber", o->weft_fiber,
                  "raytrace: the weft yarns' fiber (table, spec or preset; default --fiber)");
  sub->add_flag("--thread-colours", o->thread_colours,
                "raytrace: one fiber per thread colour of the WIF draft, --fiber dyed to the "
                "colour (docs/fabric-bsdf.md; at most " +
                    std::to_string(kMaxThreadColours) + " colours)");
  sub->add_option("--method", o->method, "summation | summation-visible | raytrace")
      ->check(CLI::IsMember({"summation", "summation-visible", "raytrace"}))
      ->capture_default_str();
  sub->add_option("--weave", o->weave, "woven sample options (.json; default: the bundled poplin)");
  sub->add_option("--pattern", o->pattern, "weave pattern: plain, twill:N/M, satin:N");
  sub->add_option("--wif", o->wif, "WIF weaving draft");
  sub->add_option("--detail", o->detail, "sample detail for the ray tracer: yarn or fiber")
      ->check(CLI::IsMember({"yarn", "fiber"}))
      ->capture_default_str();
  sub->add_option("-R,--resolution", o->resolution, "fabric table bins per hemisphere side")
      ->check(CLI::Range(1, TabulatedBsdfTable::kMaxResolution))
      ->capture_default_str();
  sub->add_option("--samples", o->samples,
                  "summations: direction pairs per cell pair (1 to " +
                      std::to_string(kMaxSummationSamples) +
                      "); raytrace: particles per incident bin (1 to 2^36)")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 36));
  sub->add_option(
         "--estimator", o->estimator,
         "raytrace: hero (one channel steers each path, MIS over channels, roulette on the "
         "largest weight, splitting; the default) | nee (hero, and the exits estimated at every "
         "scattering by next-event draws) | mean (the channels' mean steers; no splitting)")
      ->check(CLI::IsMember({"hero", "nee", "mean"}));
  sub->add_option("--next-event-rays", o->next_event_rays,
                  "raytrace, nee: draws of the exit per scattering (default " +
                      std::to_string(kDefaultNextEventRays) + ")")
      ->check(CLI::Range(1, kMaxNextEventRays));
  sub->add_option("--launch-lattice", o->launch_lattice,
                  "raytrace, nee: particles per launch block, their entry points on a lattice "
                  "over the repeat (default " +
                      std::to_string(kDefaultLaunchLattice) + ")")
      ->check(CLI::Range(1, kMaxLaunchLattice));
  sub->add_option("--straight-through", o->straight_through,
                  "raytrace: exact (the light passing between the fibers computed, the particles "
                  "book what meets a fiber; the default) | sampled (booked by the particles too)")
      ->check(CLI::IsMember({"exact", "sampled"}));
  sub->add_option("--split-threshold", o->split_threshold,
                  "raytrace, hero: split a particle whose largest channel weight exceeds this "
                  "(default " +
                      std::to_string(FabricRaytraceOptions{}.split_threshold) + ")");
  sub->add_option("--max-scatterings", o->max_scatterings,
                  "raytrace: a particle ends at its Nth scattering, its weight booked as lost, so "
                  "the table holds the paths of fewer (what each order of scattering carries; "
                  "default " +
                      std::to_string(FabricRaytraceOptions{}.max_scatterings) + ")")
      ->check(CLI::Range(1, 1000000));
  sub->add_option("--weave-out", o->weave_out,
                  "raytrace: also the weave table (.exr): how the cloth varies over its repeat, "
                  "the exits binned by where they cross the cloth's mid-plane (with --shard, the "
                  "parts carry it and `weft merge --weave-out` writes it)");
  sub->add_option("--weave-positions", o->weave_positions,
                  "raytrace, --weave-out: position cells over the repeat, N (N x N) or UxV (u "
                  "along the warp), each 1 to " +
                      std::to_string(WeaveTable::kMaxPositions) + " (default " +
                      std::to_string(kDefaultWeavePositions) + ")");
  sub->add_option("--weave-resolution", o->weave_resolution,
                  "raytrace, --weave-out: the weave table's coarse bins per hemisphere side, 1 to "
                  "the table's -R (default " +
                      std::to_string(kDefaultWeaveResolution) + ", at most -R)");
  sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
  sub->add_option("--threads", o->threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  sub->add_option("-o,--output", o->output, "output fabric table (.exr)")->required();
  sub->add_option("--shard", o->shard,
                  "raytrace: K/N, trace only shard K of N (incident bins) into a part file for "
                  "`weft merge`");
  sub->add_flag("--resume", o->resume,
                "raytrace: checkpoint finished incident bins beside the output and continue "
                "from a checkpoint an earlier run left there");
  sub->add_flag("--json", o->json, "print a JSON summary");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  commands.push_back({sub, [o](const RunLimits& l) { return run(*o, l); }});
}

int merge_fabric_bake(const JobPart& all, const std::string& output, const std::string& weave_out,
                      bool json) {
  const bool weave = all.job.contains("weave_positions");
  if (weave && weave_out.empty())
    throw Error("", "--weave-out",
                "the parts carry a weave tally (bake fabric --weave-out): give --weave-out "
                "FILE.exr for its table");
  if (!weave && !weave_out.empty())
    throw Error(weave_out, "--weave-out",
                "the parts carry no weave tally: bake them with --weave-out to have one");
  if (weave && std::filesystem::path(weave_out).extension() != ".exr")
    throw Error(weave_out, "--weave-out", "the weave table must be written to a .exr file");
  FabricRaytraceResult r = assemble_fabric_job(all);
  TabulatedBsdfTable& t = r.table;
  t.metadata["sample"] = ParamReader(all.job, "", "job").string("sample");
  t.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;  // as bake fabric writes
  t.write_exr(output);
  nlohmann::json j = {{"output", output}, {"method", "raytrace"}, {"parts_merged", true}};
  j.update(fabric_table_summary(t));
  j.update(raytrace_summary(r));
  if (weave) {
    describe_weave(t, r.weave);
    r.weave.write_exr(weave_out);
    j["weave"] = weave_summary(r, weave_out);
    if (!json) print_weave_summary(j["weave"]);
  }
  if (json)
    std::cout << j.dump(2) << "\n";
  else
    std::printf("%s: ray-traced fabric table, R = %d, merged; relative noise %.4g\n",
                output.c_str(), t.resolution, r.relative_noise);
  return 0;
}

}  // namespace weft::cli
