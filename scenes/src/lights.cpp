#include "weft/scenes/lights.h"

#include <algorithm>

namespace weft {

double PointLight::falloff(const Vec3& from_light) const {
  if (!is_spot()) return 1;
  // KHR_lights_punctual's reference falloff: squared linear ramp in cos between the cones.
  const double cd = dot(spot_direction, from_light);
  const double scale = 1.0 / std::max(1e-3, cos_inner - cos_outer);
  const double a = std::clamp((cd - cos_outer) * scale, 0.0, 1.0);
  return a * a;
}

}  // namespace weft
