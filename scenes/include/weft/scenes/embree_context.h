#pragma once
// The Embree query context of RenderScene: Embree's own, extended by the fiber that a query
// ignores. The fiber geometries' filter functions read the extension, so every query on a
// RenderScene's Embree scene (RenderScene::embree_scene) must pass one. Only code that talks to
// Embree directly (the scenes library, bench/) includes this header.
#include <embree3/rtcore.h>

#include <cstdint>

namespace weft {

struct FiberQueryContext {
  RTCIntersectContext embree;  // first member: Embree hands its address back to the filters
  int64_t ignore_fiber = -1;   // kNoFiber (render_scene.h): ignore nothing

  explicit FiberQueryContext(int64_t ignore = -1) : ignore_fiber(ignore) {
    rtcInitIntersectContext(&embree);
  }
};

}  // namespace weft
