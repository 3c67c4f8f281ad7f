#include "weft/integrators/weave_level.h"

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// Distance from p to the nearest point of 'box' (0 inside).
double distance_to_box(const Vec3& p, const Bounds3& box) {
  const double dx = std::max({box.lo.x - p.x, 0.0, p.x - box.hi.x});
  const double dy = std::max({box.lo.y - p.y, 0.0, p.y - box.hi.y});
  const double dz = std::max({box.lo.z - p.z, 0.0, p.z - box.hi.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

const char* level_name(WeaveLevel level) {
  switch (level) {
    case WeaveLevel::weave:
      return "weave";
    case WeaveLevel::table:
      return "table";
    default:
      return "auto";
  }
}

}  // namespace

double repeat_pixels(const Camera& camera, int film_height, const Bounds3& box, double repeat_m) {
  double pixel_m;
  if (camera.type == Camera::Type::orthographic) {
    pixel_m = 2 * camera.half_height / film_height;
  } else {
    const double d = distance_to_box(camera.position, box);
    if (d == 0) return std::numeric_limits<double>::infinity();
    pixel_m = 2 * d * std::tan(camera.yfov_rad / 2) / film_height;
  }
  return repeat_m / pixel_m;
}

bool weave_level_chosen(WeaveLevel level, double pixels, double min_pixels) {
  if (level == WeaveLevel::automatic) return pixels >= min_pixels;
  return level == WeaveLevel::weave;
}

std::vector<WeaveLevelChoice> choose_weave_levels(const RenderScene& scene, const Camera& camera,
                                                  const RenderSettings& settings) {
  std::vector<WeaveLevelChoice> out;
  for (const RenderScene::WovenMesh& m : scene.woven_meshes()) {
    const WeaveTable& t = m.weave->modulation->table();
    WeaveLevelChoice c;
    c.object = m.name;
    c.shape = m.shape;
    c.setting = level_name(m.weave->level);
    c.repeat_pixels =
        repeat_pixels(camera, settings.height, m.bounds, std::min(t.repeat_u_m, t.repeat_v_m));
    c.weave = weave_level_chosen(m.weave->level, c.repeat_pixels, m.weave->min_pixels);
    c.weave_file = m.weave->file;
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<uint8_t> weave_flags(const std::vector<WeaveLevelChoice>& choices) {
  std::vector<uint8_t> flags;
  for (const auto& c : choices) flags.push_back(c.weave ? 1 : 0);
  return flags;
}

nlohmann::json weave_levels_json(const std::vector<WeaveLevelChoice>& choices) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : choices)
    out.push_back(
        {{"object", c.object},
         {"mesh", c.shape},
         {"level", c.weave ? "weave" : "table"},
         {"setting", c.setting},
         {"repeat_pixels", std::isfinite(c.repeat_pixels) ? nlohmann::json(c.repeat_pixels)
                                                          : nlohmann::json(nullptr)},
         {"weave", c.weave_file}});
  return out;
}

}  // namespace weft
