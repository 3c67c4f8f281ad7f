#pragma once
// The Embree query context of RenderScene: Embree's own, extended by the fiber that a query
// ignores. The fiber geometries' filter functions read the extension, so every query on a
// RenderScene's Embree scene (RenderScene::embree_scene) must pass one. Only code that talks to
// Embree directly (the scenes library, bench/) includes this header.
#include <embree3/rtcore.h>

#include <cstdint>

#include "weft/scenes/curves.h"

namespace weft {

// The ignored fiber's first and last segments (world units; tubes: the radius of their polygon's
// corners), where a fiber cut into several curves overlaps its next piece.
struct FiberEnds {
  FiberSegment segment[2];
  Vec3 centre[2];  // their bounding spheres, to skip candidates far from them
  double reach2[2] = {0, 0};
  int count = 0;
};

struct FiberQueryContext {
  RTCIntersectContext embree;  // first member: Embree hands its address back to the filters
  int64_t ignore_fiber = -1;   // kNoFiber (render_scene.h): ignore nothing
  // The ignored fiber's ends, owned by the caller: RenderScene fills them for its own queries;
  // without them (null) only hits from inside are passed. A pointer, so that the context of a
  // query that ignores nothing (most of a path tracer's) costs no more than Embree's own.
  const FiberEnds* ends = nullptr;

  explicit FiberQueryContext(int64_t ignore = -1, const FiberEnds* ignored_ends = nullptr)
      : ignore_fiber(ignore), ends(ignored_ends) {
    rtcInitIntersectContext(&embree);
  }
};

}  // namespace weft
