// plan_fabric_bake: every check of a fabric bake before any work (fabric_bake.h).
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fabric/fabric_colour.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// The woven sample's options: the request's over those of its weave options (file or given).
WeaveOptions requested_weave_options(const FabricBakeRequest& o) {
  WeaveOptions given;
  if (!o.pattern.empty()) given.pattern = o.pattern;
  if (!o.wif.empty()) given.wif = o.wif;
  if (!o.pattern.empty() && !o.wif.empty())
    throw Error("", "wif", "give either --pattern or --wif, not both");
  given.detail = o.detail;
  const WeaveOptions base = o.weave_options   ? *o.weave_options
                            : o.weave.empty() ? WeaveOptions{}
                                              : read_weave_options(o.weave);
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
  // The curve points the sample will hold (fabric_scene_bytes counts those).
  const double points = z.made_curve_points > 0 ? z.made_curve_points : z.curve_points;
  check_memory(limits, *bytes, draft, "--detail",
               "the scene at " + z.detail + " detail (" +
                   ParamReader::fmt(yarn ? z.triangles : points) +
                   (yarn ? " triangles" : " curve points") + ")");
  return w;
}

// The sample's options into the plan, its scene's memory checked (fitted_weave_options) where the
// method builds one: the summations of the paper's method need only the sample's name.
// 'draft_in_weave': the WIF draft the weave options name.
void plan_sample(FabricBakePlan& p, const std::string& draft_in_weave) {
  const FabricBakeRequest& o = p.request;
  if (p.method == FabricMethod::kSummation) {
    p.weave = requested_weave_options(o);
    return;
  }
  const std::string draft = !o.wif.empty()            ? o.wif
                            : !draft_in_weave.empty() ? draft_in_weave
                                                      : o.weave;
  p.weave = fitted_weave_options(o.limits, requested_weave_options(o), draft,
                                 o.shard.empty() && !o.resume, &p.note, &p.scene_bytes);
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

// The weave tally's settings (weave_tally.h): on with weave_out.
void weave_tally_options(const FabricBakeRequest& o, FabricRaytraceOptions& r) {
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

// The ray tracer's settings from the request, checked before any work: options that do nothing
// in the configuration given are errors, and a bad value names its option.
FabricRaytraceOptions raytrace_options(const FabricBakeRequest& o) {
  FabricRaytraceOptions r;
  r.resolution = o.resolution;
  if (o.samples) r.particles_per_bin = *o.samples;
  r.seed = o.seed;
  r.threads = o.threads;
  const FabricEstimator estimator =
      o.estimator ? value_of(kFabricEstimators, *o.estimator, "", "--estimator")
                  : FabricEstimator::kHero;
  r.channel_sampling =
      estimator == FabricEstimator::kMean ? ChannelSampling::mean : ChannelSampling::spectral_mis;
  if (o.next_event_rays && estimator != FabricEstimator::kNee)
    throw Error("", "--next-event-rays",
                "next-event rays are the nee estimator's: give --estimator nee");
  if (o.launch_lattice && estimator != FabricEstimator::kNee)
    throw Error("", "--launch-lattice",
                "launch blocks are the nee estimator's: give --estimator nee");
  if (estimator == FabricEstimator::kNee) {
    r.next_event_rays = o.next_event_rays.value_or(kDefaultNextEventRays);
    r.launch_lattice = o.launch_lattice.value_or(kDefaultLaunchLattice);
  }
  if (o.straight_through)
    r.straight_through =
        value_of(kStraightThroughNames, *o.straight_through, "", "--straight-through");
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
  if (o.sheen_window && !o.sheen_resolution)
    throw Error("", "--sheen-window", "sizes the sheen's window: give --sheen-resolution too");
  if (o.sheen_light_resolution && !o.sheen_resolution)
    throw Error("", "--sheen-light-resolution",
                "sizes the sheen's light bins: give --sheen-resolution too");
  if (o.sheen_light && !o.sheen_resolution)
    throw Error("", "--sheen-light", "chooses the sheen's light: give --sheen-resolution too");
  if (o.sheen_resolution) {
    if (!o.shard.empty() || o.resume)
      throw Error("", "--sheen-resolution",
                  "is booked for a whole table only: not with --shard or --resume");
    r.sheen_h_resolution = *o.sheen_resolution;
    if (o.sheen_window) r.sheen_window = *o.sheen_window;
    HalfVectorLobe::check_shape(r.sheen_h_resolution, r.sheen_window, "", "--sheen-resolution",
                                "--sheen-window");
    if (o.sheen_light)
      r.sheen_light = value_of(kSheenLightNames, *o.sheen_light, "", "--sheen-light");
    if (o.sheen_light_resolution) {
      r.sheen_light_resolution = *o.sheen_light_resolution;
      HalfVectorLobe::check_light_resolution(r.resolution, r.sheen_light_resolution, "",
                                             "--sheen-light-resolution");
    }
  }
  weave_tally_options(o, r);
  r.validate();
  return r;
}

// The work's time from a lower bound of its rate, before any (check_fabric_bake): a ray trace's
// incident bins are those of its shard.
void check_fabric_work(const FabricBakePlan& p) {
  const FabricBakeRequest& o = p.request;
  const uint64_t bins = static_cast<uint64_t>(DirectionGrid{o.resolution}.bins());
  const UnitRange r =
      p.method == FabricMethod::kRaytrace
          ? shard_units(bins, o.shard.empty() ? Shard{} : parse_shard(o.shard, "--shard"))
          : UnitRange{0, bins};
  check_fabric_bake(o.limits, p.method, o.resolution, r.last - r.first, o.samples, o.threads,
                    "--samples");
}

// The choices the command line's own checks make before the request is formed, for the front
// ends that have none (Python).
FabricMethod checked_choices(const FabricBakeRequest& o) {
  const FabricMethod method = value_of(kFabricMethods, o.method, "", "--method");
  if (o.detail && *o.detail != "yarn" && *o.detail != "fiber")
    throw Error("", "--detail", "must be 'yarn' or 'fiber', got '" + *o.detail + "'");
  if (o.resolution < 1 || o.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "--resolution",
                "must be in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "], got " +
                    std::to_string(o.resolution));
  return method;
}

// The ray tracer's options given to a summation, and a summation's sample count, refused.
void check_method_options(const FabricBakeRequest& o, FabricMethod method) {
  const bool raytrace = method == FabricMethod::kRaytrace;
  if ((!o.shard.empty() || o.resume) && !raytrace)
    throw Error("", "--shard", "--shard and --resume need --method raytrace");
  if (!raytrace && o.estimator)
    throw Error("", "--estimator", "the estimator is the ray tracer's: it needs --method raytrace");
  // Checked before narrowing to the summation's int: 2^32 + 1 wrapped to 1.
  if (!raytrace && o.samples && (*o.samples < 1 || *o.samples > kMaxSummationSamples))
    throw Error("", "--samples",
                "a summation takes 1 to " + std::to_string(kMaxSummationSamples) +
                    " direction pairs per cell pair, got " + std::to_string(*o.samples));
  if (!raytrace && o.straight_through)
    throw Error("", "--straight-through", "the ray tracer's: it needs --method raytrace");
  if (!raytrace && o.max_scatterings)
    throw Error("", "--max-scatterings", "the ray tracer's: it needs --method raytrace");
  if (!raytrace && o.split_threshold)
    throw Error("", "--split-threshold",
                "splitting is the ray tracer's: it needs --method raytrace");
  if (!raytrace && (!o.weave_out.empty() || o.weave_positions || o.weave_resolution))
    throw Error("", o.weave_out.empty() ? "--weave-positions" : "--weave-out",
                "the weave table is the ray tracer's: it needs --method raytrace");
  if (!o.weave_out.empty() && std::filesystem::path(o.weave_out).extension() != ".exr")
    throw Error(o.weave_out, "--weave-out", "the weave table must be written to a .exr file");
}

}  // namespace

FabricBakePlan plan_fabric_bake(const FabricBakeRequest& o) {
  FabricBakePlan p;
  p.request = o;
  p.method = checked_choices(o);
  check_method_options(o, p.method);
  if (p.method == FabricMethod::kRaytrace) p.raytrace = raytrace_options(o);
  // The WIF draft weave options name is read too.
  const std::string weave_wif = o.weave_options   ? o.weave_options->wif.value_or("")
                                : o.weave.empty() ? ""
                                                  : read_weave_options(o.weave).wif.value_or("");
  p.fibers = {.fiber = o.fiber,
              .warp_fiber = o.warp_fiber,
              .weft_fiber = o.weft_fiber,
              .fiber_table = o.fiber_table,
              .thread_colours = o.thread_colours,
              .draft = o.wif.empty() ? weave_wif : o.wif,
              .limits = o.limits};
  if (o.thread_colour_method) {
    if (!o.thread_colours)
      throw Error("", "--thread-colour-method",
                  "chooses how --thread-colours dyes the fiber: give --thread-colours");
    p.fibers.thread_colour_method =
        value_of(kThreadColourMethods, *o.thread_colour_method, "", "--thread-colour-method");
  }
  check_fabric_fiber_options(p.fibers, p.method == FabricMethod::kRaytrace);
  if (o.thread_colours && p.fibers.thread_colour_method == ThreadColourMethod::kMatch)
    check_thread_colour_match(o, thread_colour_count(p.fibers.draft));
  if (!o.colour.empty()) p.colour = check_fabric_colour(o, p.method);
  validate_output_paths(
      o.limits,
      {{o.output, "--output"},
       {o.output.empty() ? std::filesystem::path() : checkpoint_path(o.output), "checkpoint"},
       {o.weave_out, "--weave-out"}},
      {{o.fiber, "fiber table or spec"},
       {o.warp_fiber, "warp fiber table or spec"},
       {o.weft_fiber, "weft fiber table or spec"},
       {o.weave, "weave options"},
       {o.wif, "WIF draft"},
       {weave_wif, "WIF draft"},
       {".weft-cache", "fiber-table bake cache"}});
  if (!o.output.empty() && std::filesystem::path(o.output).extension() != ".exr" && o.shard.empty())
    throw Error(o.output, "", "the fabric table must be written to a .exr file");
  check_fabric_work(p);
  plan_sample(p, weave_wif);
  if (o.sheen_resolution && p.weave.detail.value_or("yarn") != "fiber")
    throw Error("", "--sheen-resolution",
                "books the fibers' surface lobe: it needs --detail fiber");
  return p;
}

}  // namespace weft
