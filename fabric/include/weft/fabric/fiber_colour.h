#pragma once
// `weft bake fiber --colour` and weft.bake_fiber(colour=): the bake of a fiber spec whose dyes are
// first scaled so that a cloth made of the fiber meets the colour (docs/colour.md). A fiber alone
// has no colour a d/8 instrument reads: the reading is a cloth's, the one `weft bake fabric
// --colour` takes (fabric_colour.h), of a fiber-level ray trace of the request's colour_weave (the
// bundled poplin unless given) at a fabric bake's defaults. The fiber table is then baked of the
// matched spec at the request's own settings: the dyes' depths are the spec's, the bake's
// photons and resolution only its noise.
#include <functional>
#include <optional>
#include <string>

#include "weft/fabric/fabric_bake.h"
#include "weft/fiber/fiber_bake_request.h"

namespace weft {

struct ColouredFiberBakePlan {
  FiberBakePlan fiber;                    // the bake (of the recipe as written until matched)
  std::optional<FabricBakePlan> reading;  // the cloth that reads the colour; none without one
};

// The fiber bake's checks (plan_fiber_bake) and, with a colour, the reading cloth's
// (plan_fabric_bake of the ray trace at fiber detail with the request's colour_weave, seed,
// threads and limits: the target, the spec's recipe, the sample, the readings' time), all before
// any work. weft::Error naming the option: a colour with a spec given as a dict (the match reads
// the spec by name), with a shard or a resumed bake (their records name the spec's file, not the
// matched dyes), and colour_weave without a colour are refused.
ColouredFiberBakePlan plan_coloured_fiber_bake(
    const FiberBakeRequest& request, const std::function<void(const std::string&)>& warn = {});

// The match (cached by its inputs, as a fabric bake's is), then the bake of the matched spec with
// the table's metadata "colour" and the summary's colour_match as `weft bake fabric --colour`
// gives them. Interrupted during the match: interrupted_before_work, nothing written.
FiberBakeOutcome run_coloured_fiber_bake(const ColouredFiberBakePlan& plan,
                                         const FiberBakeHooks& hooks = {});

}  // namespace weft
