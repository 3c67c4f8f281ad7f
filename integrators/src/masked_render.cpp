#include "weft/integrators/masked_render.h"

#include "weft/core/error.h"

namespace weft {

MaskedRender render_masked(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
                           const std::vector<uint8_t>& mask_meshes,
                           const ProgressCallback& progress) {
  if (mask_meshes.size() != scene.shape_count())
    throw Error("", "render", "mask does not match the shape count");
  MaskedRender out;
  // render() rejects a bad size; until then, allocate nothing for it.
  const size_t npx = s.width > 0 && s.height > 0 ? size_t(s.width) * s.height : 0;
  std::vector<uint32_t> hits(npx, 0);
  out.sum.assign(3 * npx, 0.0);
  out.sum_sq.assign(3 * npx, 0.0);
  RenderObservers observers;
  observers.on_sample = [&](uint64_t pixel, int64_t first_mesh, const Rgb& L) {
    if (first_mesh < 0 || !mask_meshes[first_mesh]) return;
    ++hits[pixel];
    const double c[3] = {L.r, L.g, L.b};
    for (int i = 0; i < 3; ++i)
      out.sum[3 * pixel + i] += c[i], out.sum_sq[3 * pixel + i] += c[i] * c[i];
  };
  out.render = render(scene, camera, s, progress, observers);
  const double inv_spp = 1.0 / s.spp;
  out.coverage.resize(npx);
  for (size_t p = 0; p < npx; ++p) {
    out.coverage[p] = static_cast<float>(hits[p] * inv_spp);
    for (int i = 0; i < 3; ++i) out.sum[3 * p + i] *= inv_spp, out.sum_sq[3 * p + i] *= inv_spp;
  }
  return out;
}

}  // namespace weft
