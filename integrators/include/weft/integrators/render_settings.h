#pragma once
// What the path tracer is told, and the scene description's "render" section that sets it:
//
//   "render": {"width": 256, "height": 256, "spp": 16, "max_depth": 16, "rr_depth": 3, "seed": 0,
//              "crop": [x0, x1, y0, y1], "time_limit_s": 60, "spectral": false}
//
// Every key is optional; the defaults are RenderSettings{}, the renderer's one set of defaults
// (the command line and the benchmarks start from it too).
#include <cstdint>
#include <optional>
#include <string>

#include "weft/scenes/description.h"

namespace weft {

// Which strategies estimate light from area lights and the environment (delta lights always use
// next-event estimation). The single-strategy modes exist to test MIS against each of its parts.
enum class LightSampling { mis, lights_only, bsdf_only };

// A window of the film in pixels, x0 <= x < x1 and y0 <= y < y1 (pbrt-v4's "pixelbounds"): its
// pixels are those of the whole film's render, bit for bit.
struct PixelWindow {
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool operator==(const PixelWindow&) const = default;
};

struct RenderSettings {
  int width = 256, height = 256;
  int spp = 16;
  int max_depth = 16;  // bounces; 0 = emitted light only, 1 = direct lighting
  int rr_depth = 3;    // bounces before Russian roulette
  uint64_t seed = 0;
  int threads = 0;  // 0 = all cores
  int tile_size = 16;
  LightSampling sampling = LightSampling::mis;
  std::optional<PixelWindow> crop;  // render only this window of the width x height film
  // Seconds after which the render stops at the end of a whole pass (one sample per pixel of the
  // window); the image is then the mean of the passes done (RenderResult::spp_done). 0: no limit.
  double time_limit_s = 0;
  // Extra passes of the first surface each camera sample sees (RenderResult::albedo, normal).
  bool aov_albedo = false, aov_normal = false;
  // Light transport per wavelength band instead of in RGB (path_tracer.h): for scenes of spectral
  // tables, whose light scattered many times is not the RGB reduction's (multiple scattering does
  // not commute with reducing a spectrum to three numbers). Every material needs spectral values
  // and every light a grey colour (RenderScene::check_spectral). The image is linear sRGB either
  // way.
  bool spectral = false;
  // Besides the image, one image per light of the scene (RenderResult::light_images), each the
  // light that light alone gives: the paths are traced once for all of them. At most
  // kMaxLightGroups lights, no time limit. A scene's parallel lights draw no random numbers, so
  // each of their images has the bits of a render with that light alone.
  bool light_groups = false;
};
inline constexpr int kMaxLightGroups = 4;

// A lower bound on the CPU time of one path sample (one pixel sample), seconds: a sample traces at
// least its camera ray, and the path tracer ran 8.46 M rays/s on 2 threads on the 65 536-triangle
// woven patch (PERFORMANCE.md, 0.24 us per ray per core); a scene of a few triangles is faster,
// so 0.05 us. A front end estimates a render's or sweep's time with it before starting.
inline constexpr double kMinSecondsPerPathSample = 0.05e-6;

// RenderSettings{} with the description's "render" section applied. Unknown keys and bad values
// are weft::Error naming the description's file and the key's path ("render.spp").
RenderSettings render_settings_from(const SceneDescription& desc);

// Error naming 'file' and 'field' unless the window lies on the width x height film and is not
// empty.
void check_crop(const PixelWindow& window, int width, int height, const std::string& file,
                const std::string& field);

}  // namespace weft
