#pragma once
// What the path tracer is told, and the scene description's "render" section that sets it:
//
//   "render": {"width": 256, "height": 256, "spp": 16, "max_depth": 16, "rr_depth": 3, "seed": 0}
//
// Every key is optional; the defaults are RenderSettings{}, the renderer's one set of defaults
// (the command line and the benchmarks start from it too).
#include <cstdint>

#include "weft/scenes/description.h"

namespace weft {

// Which strategies estimate light from area lights and the environment (delta lights always use
// next-event estimation). The single-strategy modes exist to test MIS against each of its parts.
enum class LightSampling { mis, lights_only, bsdf_only };

struct RenderSettings {
  int width = 256, height = 256;
  int spp = 16;
  int max_depth = 16;  // bounces; 0 = emitted light only, 1 = direct lighting
  int rr_depth = 3;    // bounces before Russian roulette
  uint64_t seed = 0;
  int threads = 0;  // 0 = all cores
  int tile_size = 16;
  LightSampling sampling = LightSampling::mis;
};

// RenderSettings{} with the description's "render" section applied. Unknown keys and bad values
// are weft::Error naming the description's file and the key's path ("render.spp").
RenderSettings render_settings_from(const SceneDescription& desc);

}  // namespace weft
