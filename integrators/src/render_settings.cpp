#include "weft/integrators/render_settings.h"

#include <limits>

#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft {

void check_crop(const PixelWindow& w, int width, int height, const std::string& file,
                const std::string& field) {
  if (!(0 <= w.x0 && w.x0 < w.x1 && w.x1 <= width && 0 <= w.y0 && w.y0 < w.y1 && w.y1 <= height))
    throw Error(file, field,
                "window [" + std::to_string(w.x0) + ", " + std::to_string(w.x1) + ", " +
                    std::to_string(w.y0) + ", " + std::to_string(w.y1) +
                    "] must satisfy 0 <= x0 < x1 <= width (" + std::to_string(width) +
                    ") and 0 <= y0 < y1 <= height (" + std::to_string(height) + ")");
}

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
  if (p.has("crop")) {
    const auto& c = p.at("crop");
    if (!c.is_array() || c.size() != 4)
      throw Error(desc.source, p.field("crop"), "must be [x0, x1, y0, y1] (pixels)");
    int v[4];
    for (int i = 0; i < 4; ++i)
      v[i] = static_cast<int>(
          p.check_number(c[i], p.field("crop") + "[" + std::to_string(i) + "]", 0, 16384));
    s.crop = PixelWindow{v[0], v[1], v[2], v[3]};
    for (int i = 0; i < 4; ++i)
      if (double(v[i]) != c[i].get<double>())
        throw Error(desc.source, p.field("crop"), "must be whole pixels");
    check_crop(*s.crop, s.width, s.height, desc.source, p.field("crop"));
  }
  s.time_limit_s = p.number("time_limit_s", s.time_limit_s, 0, 1e9);
  s.spectral = p.boolean("spectral", s.spectral);
  p.finish();
  return s;
}

}  // namespace weft
