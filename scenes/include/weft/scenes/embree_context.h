#pragma once
// The Embree query context of RenderScene: Embree's own, extended by the fiber that a query
// ignores. The fiber geometries' filter functions read the extension, so every query on a
// RenderScene's Embree scene (RenderScene::embree_scene) must pass one. Only code that talks to
// Embree directly (the scenes library, bench/) includes this header.
#include <embree3/rtcore.h>

#include <cstdint>

#include "weft/scenes/curves.h"

namespace weft {

struct FiberQueryContext {
  RTCIntersectContext embree;  // first member: Embree hands its address back to the filters
  int64_t ignore_fiber = -1;   // kNoFiber (render_scene.h): ignore nothing
  // The ignored fiber's first and last segments (world units; tubes: the radius of their polygon's
  // corners), where a fiber cut into several curves overlaps its next piece: RenderScene fills
  // them for its own queries; without them (end_count 0) only hits from inside are passed.
  FiberSegment ends[2];
  Vec3 end_centre[2];  // their bounding spheres, to skip candidates far from them
  double end_reach2[2] = {0, 0};
  int end_count = 0;

  explicit FiberQueryContext(int64_t ignore = -1) : ignore_fiber(ignore) {
    rtcInitIntersectContext(&embree);
  }
};

}  // namespace weft
