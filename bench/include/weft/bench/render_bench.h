#pragma once
// Render throughput measurements (`weft bench render`, bench_render.cpp): raw Embree
// rtcIntersect1 on diffuse rays against the path tracer's rays per second on the same scene, the
// path tracer's own rays replayed through bare Embree, and the path tracer's 1 -> 2 thread
// speed-up. Timing lives here and in bench/, never in unit tests.
#include <cstddef>
#include <cstdint>
#include <string>

#include "weft/integrators/render_settings.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

namespace weft {

// A ray in Embree's single precision, as the path tracer hands it over (RenderScene's queries
// convert the same way).
struct EmbreeRay {
  float org[3], dir[3], tmax;
  bool shadow;  // rtcOccluded1 rather than rtcIntersect1
};
EmbreeRay to_embree(const Ray& ray, bool shadow);

// Bare Embree queries on the scene's BVH, without surface reconstruction: the baseline.
// Hit distance (infinity for none); whether anything lies within tmax.
double embree_hit_distance(const RenderScene& scene, const EmbreeRay& ray);
bool embree_occluded(const RenderScene& scene, const EmbreeRay& ray);

inline constexpr int kMaxBenchRepeats = 1000;

struct RenderBenchOptions {
  size_t diffuse_rays = 1 << 20;  // for the Embree baseline
  int threads = 2;  // the "many threads" side of the speed-up and of the throughput ratios
  // Times every measurement is made (1 to kMaxBenchRepeats): the ratios are taken within each
  // repeat, the figures reported as medians, the ratio to the replay with its range as well.
  int repeats = 5;
  // The path-traced image (its own 'threads' is replaced: 1, then 'threads'); its seed also seeds
  // the diffuse rays.
  RenderSettings render;
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
  double ratio_replay = 0;  // the median over the repeats of the ratio within each
  double ratio_replay_min = 0, ratio_replay_max = 0;  // its range over the repeats
  int repeats = 0;
  // The same render with the packets off (RenderScene::with_ray_packets: the same image): its
  // rays per second, its ratio to the replay and the ratio of the two renders' rates, medians
  // over the repeats. ray_packets: whether this machine's Embree answers packets at all (when
  // not, both renders go one by one and the gain is 1 within noise).
  bool ray_packets = false;
  double path_rays_per_s_one_by_one = 0, ratio_replay_one_by_one = 0, packet_gain = 0;
  double path_rays_per_s_1thread = 0;
  double speedup = 0;  // path_rays_per_s / path_rays_per_s_1thread
  // The same 1 -> 'threads' speed-up for pure arithmetic tasks, measured in the same run: what the
  // machine offers right now (shared machines often do not give a second free core).
  double machine_speedup = 0;
};

// A woven patch in memory (lambert warp and weft, a parallel light at 30 degrees, orthographic
// camera framing the patch from 20 degrees).
SceneDescription weave_bench_scene(const WeaveParams& params);
// The benchmarks' lighting and yarn materials: Lambertian "warp" (red) and "weft" (grey), a
// directional light at 30 degrees from the normal.
void add_bench_materials_and_sun(SceneDescription& d);

RenderBenchResult bench_render_scene(const SceneDescription& desc, const std::string& name,
                                     const RenderBenchOptions& options);

}  // namespace weft
