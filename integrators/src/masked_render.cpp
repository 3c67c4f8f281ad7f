#include "weft/integrators/masked_render.h"

#include "weft/core/error.h"
#include "zero_polled.h"

namespace weft {

MaskedRender render_masked(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
                           const std::vector<uint8_t>& mask_meshes,
                           const ProgressCallback& progress) {
  if (mask_meshes.size() != scene.shape_count())
    throw Error("", "render", "mask does not match the shape count");
  MaskedRender out;
  // render() rejects a bad size; until then, allocate nothing for it.
  const size_t npx = s.width > 0 && s.height > 0 ? size_t(s.width) * s.height : 0;
  // Zeroed in slices with polls between them (zero_polled.h): 52 bytes a pixel, 14 GB at 16384 x
  // 16384, made before render() polls at all.
  const auto keep_going = [&] { return progress({"render", 0, uint64_t(npx) * s.spp, "samples"}); };
  std::vector<uint32_t> hits;
  if (!zero_polled(hits, npx, keep_going) || !zero_polled(out.sum, 3 * npx, keep_going) ||
      !zero_polled(out.sum_sq, 3 * npx, keep_going)) {
    out.render.cancelled = true;
    return out;
  }
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
