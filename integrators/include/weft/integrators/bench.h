#pragma once
// Render throughput measurements: raw Embree rtcIntersect1 on diffuse rays against the path
// tracer's rays per second on the same scene, and the path tracer's 1 -> 2 thread speed-up.
// Timing lives here and in bench/, never in unit tests.
#include <cstdint>
#include <string>

#include "weft/scenes/description.h"
#include "weft/scenes/weave.h"

namespace weft {

// A ray as the path tracer handed it to Embree (for replaying the same rays).
struct LoggedRay {
  float org[3], dir[3], tmax;
  bool shadow;  // rtcOccluded1 rather than rtcIntersect1
};

struct RenderBenchOptions {
  size_t diffuse_rays = 1 << 20;
  int width = 256, height = 256, spp = 4;
  int threads = 2;  // the "many threads" side of the speed-up and of the throughput ratio
  uint64_t seed = 1;
};

struct RenderBenchResult {
  std::string name;
  size_t triangles = 0;
  double build_s = 0;
  double embree_rays_per_s = 0;          // rtcIntersect1, diffuse rays, 'threads' threads
  double path_rays_per_s = 0;            // all path-tracer rays (camera, bounce, shadow), 'threads'
  double path_intersect_rays_per_s = 0;  // camera and bounce rays only
  double ratio = 0;                      // path_rays_per_s / embree_rays_per_s
  // The path tracer's own rays (logged, then replayed through bare rtcIntersect1/rtcOccluded1 on
  // 'threads' threads): the like-for-like baseline, so ratio_replay is the share of the path
  // tracer's time that Embree takes.
  double embree_replay_rays_per_s = 0;
  double ratio_replay = 0;
  double path_rays_per_s_1thread = 0;
  double speedup = 0;  // path_rays_per_s / path_rays_per_s_1thread
  // The same 1 -> 'threads' speed-up for pure arithmetic tasks, measured in the same run: what the
  // machine offers right now (shared machines often do not give a second free core).
  double machine_speedup = 0;
};

// A woven patch in memory (lambert warp and weft, a parallel light at 30 degrees, orthographic
// camera framing the patch from 20 degrees).
SceneDescription weave_bench_scene(const WeaveParams& params);

RenderBenchResult bench_render_scene(const SceneDescription& desc, const std::string& name,
                                     const RenderBenchOptions& options);

}  // namespace weft
