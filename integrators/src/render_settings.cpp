#include "weft/integrators/render_settings.h"

#include <limits>

#include "weft/core/params.h"

namespace weft {

RenderSettings render_settings_from(const SceneDescription& desc) {
  RenderSettings s;
  if (!desc.render) return s;
  ParamReader p(*desc.render, desc.source, "render");
  s.width = static_cast<int>(p.integer("width", s.width, 1, 16384));
  s.height = static_cast<int>(p.integer("height", s.height, 1, 16384));
  s.spp = static_cast<int>(p.integer("spp", s.spp, 1, 1 << 20));
  s.max_depth = static_cast<int>(p.integer("max_depth", s.max_depth, 0, 100000));
  s.rr_depth = static_cast<int>(p.integer("rr_depth", s.rr_depth, 0, 100000));
  s.seed = p.count("seed", s.seed, 0, std::numeric_limits<uint64_t>::max());
  p.finish();
  return s;
}

}  // namespace weft
