#pragma once
// Lights that are not geometry: parallel (delta directional), point and spot, and a constant
// environment. Emissive surfaces are area lights and live with the geometry (render_scene.h).
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft {

// A parallel beam: irradiance on a surface facing it, arriving from 'to_light'.
struct DirectionalLight {
  Vec3 to_light{0, 1, 0};  // unit, from the scene towards the light
  Rgb irradiance{1.0};     // W/m^2 per channel, on a plane perpendicular to the beam
};

// Point light of radiant intensity 'intensity' (W/sr); a spot when cos_outer > -1, with the
// smooth angular falloff of KHR_lights_punctual between the inner and outer cone.
struct PointLight {
  Vec3 position{0, 0, 0};
  Rgb intensity{1.0};
  Vec3 spot_direction{0, 0, -1};  // unit, the direction the spot shines to
  double cos_inner = -1, cos_outer = -1;

  bool is_spot() const { return cos_outer > -1; }
  double falloff(const Vec3& from_light) const;  // 1 for a point light
};

struct Lights {
  std::vector<DirectionalLight> directional;
  std::vector<PointLight> points;
  Rgb environment{0.0};  // constant radiance arriving from every direction
};

}  // namespace weft
