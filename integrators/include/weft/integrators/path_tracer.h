#pragma once
// Unidirectional path tracer over a RenderScene. At every surface, next-event estimation takes one
// sample of every light through the Light interface (lights.h); for area lights and the
// environment it is combined with BSDF sampling by multiple importance sampling (power heuristic,
// Veach 1997 ch. 9), delta lights have only that one strategy. Russian roulette after rr_depth
// bounces; shading in the mesh's tangent frame; two-sided (the BSDF sees wo below its normal and
// decides); transmission continues through the surface. Every random number of a camera sample
// comes from Rng(seed, pixel index, sample index) and tiles write disjoint pixels, so images are
// bit-identical at any thread count.
#include <cstdint>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/integrators/image.h"
#include "weft/integrators/render_settings.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/render_scene.h"

namespace weft {

// A ray as the tracer handed it to Embree (for replaying the same rays in benchmarks).
struct LoggedRay {
  float org[3], dir[3], tmax;
  bool shadow;  // rtcOccluded1 rather than rtcIntersect1
};

struct RayCounts {
  uint64_t camera = 0, bounce = 0, shadow = 0;
  uint64_t total() const { return camera + bounce + shadow; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera, bounce += o.bounce, shadow += o.shadow;
    return *this;
  }
};

struct RenderResult {
  Image image;  // mean radiance per pixel, linear RGB
  // With mask_meshes set (else empty), per pixel: the fraction of samples whose camera ray hit the
  // mask, and over those samples the sums of radiance and squared radiance divided by spp.
  std::vector<float> coverage;
  std::vector<double> masked_sum, masked_sum_sq;  // 3 per pixel
  RayCounts rays;
  std::vector<LoggedRay> ray_log;  // with log_rays, in tile order
  uint64_t nonfinite_samples = 0;  // dropped (counted, never hidden)
  bool cancelled = false;          // the progress callback asked to stop; results are partial
};

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& settings,
                    const ProgressCallback& progress = no_progress());

// Radiance arriving along 'ray' (one path sample). 'first_mesh' receives the mesh the ray hits
// first (-1 for none). Exposed for tests of the estimator itself.
Rgb trace_path(const RenderScene& scene, const Ray& ray, const RenderSettings& settings, Rng& rng,
               RayCounts& rays, int64_t* first_mesh = nullptr,
               std::vector<LoggedRay>* log = nullptr);

}  // namespace weft
