#pragma once
// A render that also measures an object mask: per pixel, how many camera samples first hit one of
// a set of shapes (meshes and fiber curve sets), and the moments of their radiance. The
// gonioreflectometer's measurement (gonio.h) and the coverage image of `weft render --mask`
// (render_job.h) are made of this.
#include <cstdint>
#include <vector>

#include "weft/integrators/path_tracer.h"

namespace weft {

struct MaskedRender {
  RenderResult render;  // the image, exactly as render() makes it
  // Per pixel: the fraction of samples whose camera ray first hit the mask, and over those samples
  // the sums of radiance and of squared radiance divided by spp (3 per pixel).
  std::vector<float> coverage;
  std::vector<double> sum, sum_sq;
};

// 'mask_meshes' holds one flag per shape of the scene (SceneDescription::select_object).
MaskedRender render_masked(const RenderScene& scene, const Camera& camera,
                           const RenderSettings& settings, const std::vector<uint8_t>& mask_meshes,
                           const ProgressCallback& progress = no_progress());

}  // namespace weft
