// glTF KHR_lights_punctual lights, converted to Weft's radiometric lights (lights.h).
#include "gltf_internal.h"
#include "message_format.h"
#include "weft/core/math.h"

namespace weft::gltf_detail {
namespace {

using detail::format_number;

std::string format_rgb(const Rgb& c) {
  return detail::format_triple(c.r, c.g, c.b);
}

Rgb light_color(const Ctx& c, const tinygltf::Light& l, const std::string& field) {
  Rgb color(1.0);
  if (!l.color.empty()) {
    if (l.color.size() != 3 || !finite_all(l.color))
      fail(c, field + ".color", "needs 3 finite numbers");
    color = {l.color[0], l.color[1], l.color[2]};
  }
  if (!std::isfinite(l.intensity) || l.intensity < 0)
    fail(c, field + ".intensity", "must be finite and >= 0");
  if (color.r < 0 || color.g < 0 || color.b < 0) fail(c, field + ".color", "must be >= 0");
  return color * l.intensity;
}

}  // namespace

void load_light(const Ctx& c, const tinygltf::Node& node, const Affine& world,
                const std::string& field) {
  const auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end()) return;
  const std::string ef = field + ".extensions.KHR_lights_punctual.light";
  if (!it->second.IsObject() || !it->second.Has("light") || !it->second.Get("light").IsNumber())
    fail(c, ef, "is required and must be a number");
  const int index = it->second.Get("light").GetNumberAsInt();
  if (index < 0 || static_cast<size_t>(index) >= c.model.lights.size())
    fail(c, ef, "light index " + std::to_string(index) + " out of range");
  const auto& l = c.model.lights[index];
  const std::string lf = "extensions.KHR_lights_punctual.lights[" + std::to_string(index) + "]";
  const Rgb color = light_color(c, l, lf);
  // Lights shine along their local -z.
  const Vec3 axis = world.vector({0, 0, -1});
  if (!(length(axis) > 0) || !is_finite(axis))
    fail(c, field, "light transform is singular or not finite");
  // KHR_lights_punctual intensities are photometric; Weft's lights are radiometric (lights.h).
  const bool photometric = c.light_units == GltfLightUnits::photometric;
  const Rgb radiometric = photometric ? color / kLuminousEfficacy_lm_per_W : color;
  const std::string what = lf + (l.name.empty() ? "" : " '" + l.name + "'") + " (" + l.type + ")";
  if (l.type == "directional") {
    c.out->lights.directional.push_back({-normalize(axis), radiometric});
    c.out->notes.push_back(c.file + ": " + what + ": " + format_number(l.intensity) +
                           (photometric ? " lux" : " (radiometric)") + " -> irradiance " +
                           format_rgb(radiometric) + " W/m^2");
  } else if (l.type == "point" || l.type == "spot") {
    PointLight p;
    p.position = world.point({0, 0, 0});
    if (!in_traceable_range(p.position))
      fail(c, field, "light position out of range after transform");
    p.intensity = radiometric;
    c.out->notes.push_back(c.file + ": " + what + ": " + format_number(l.intensity) +
                           (photometric ? " cd" : " (radiometric)") + " -> radiant intensity " +
                           format_rgb(radiometric) + " W/sr");
    if (l.type == "spot") {
      const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
      if (!(inner >= 0 && inner < outer && outer <= kPi / 2))
        fail(c, lf + ".spot", "needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
      p.spot_direction = normalize(axis);
      p.cos_inner = std::cos(inner);
      p.cos_outer = std::cos(outer);
    }
    c.out->lights.points.push_back(p);
  } else {
    fail(c, lf + ".type", "unknown light type '" + l.type + "'");
  }
}

}  // namespace weft::gltf_detail
