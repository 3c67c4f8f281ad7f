#include "weft/fabric/fiber_colour.h"

#include "weft/core/error.h"
#include "weft/fabric/fabric_colour.h"

namespace weft {
namespace {

// The fabric bake whose normal-incidence reading is the cloth's colour: the fiber-level ray trace
// of the colour's sample at a fabric bake's defaults, writing nothing.
FabricBakeRequest reading_request(const FiberBakeRequest& r) {
  FabricBakeRequest f;
  f.fiber = r.spec;
  f.colour = r.colour;
  f.method = name_of(kFabricMethods, FabricMethod::kRaytrace);
  f.detail = "fiber";
  f.weave = r.colour_weave;
  f.seed = r.seed;
  f.threads = r.threads;
  f.limits = r.limits;
  return f;
}

}  // namespace

ColouredFiberBakePlan plan_coloured_fiber_bake(
    const FiberBakeRequest& request, const std::function<void(const std::string&)>& warn) {
  FiberBakeRequest bake = request;
  bake.colour.clear();
  bake.colour_weave.clear();
  ColouredFiberBakePlan p;
  if (request.colour.empty()) {
    if (!request.colour_weave.empty())
      throw Error(
          request.colour_weave, fiber_option_name(request, "colour_weave"),
          "is the cloth that reads " + fiber_option_name(request, "colour") + ": give both");
    p.fiber = plan_fiber_bake(bake, warn);
    return p;
  }
  const std::string colour = fiber_option_name(request, "colour");
  if (request.spec_read)
    throw Error("", colour,
                "matches a spec's dyes through its file or preset name (the cloth's reading "
                "bakes it by name); give the spec as a file");
  if (!request.shard.empty() || request.resume)
    throw Error("", colour,
                "a sharded or resumed bake records the spec's file, not its matched dyes: bake "
                "the whole table with " +
                    colour);
  p.fiber = plan_fiber_bake(bake, warn);
  p.reading = plan_fabric_bake(reading_request(request));
  return p;
}

FiberBakeOutcome run_coloured_fiber_bake(const ColouredFiberBakePlan& p,
                                         const FiberBakeHooks& hooks) {
  if (!p.reading) return run_fiber_bake(p.fiber, hooks);
  FiberBakeOutcome out;
  const WovenSample sample = make_woven_sample(p.reading->weave, hooks.progress);
  if (sample.cancelled || hooks.interrupted()) {
    out.interrupted_before_work = true;
    return out;
  }
  const FabricColourMatch colour = match_fabric_colour(*p.reading, sample, hooks.progress);
  if (colour.match.cancelled || hooks.interrupted()) {
    out.interrupted_before_work = true;
    return out;
  }
  // The bake of the matched spec, planned again (its checks are the same; the dyes changed).
  FiberBakeRequest bake = p.fiber.request;
  bake.spec_read = colour.match.spec;
  bake.table_metadata.emplace_back("colour", colour_metadata(colour));
  out = run_fiber_bake(plan_fiber_bake(bake), hooks);
  if (out.table) {
    // The match's readings are the cloth's: a fiber table has no d/8 reading of its own.
    nlohmann::json j = colour_match_summary(colour.match);
    j["cached"] = colour.cached;
    j["cloth"] = sample.summary.source + " (" + sample.summary.detail + "), ray-traced";
    j["note"] = colour_match_note(colour);
    out.summary["colour_match"] = j;
  }
  return out;
}

}  // namespace weft
