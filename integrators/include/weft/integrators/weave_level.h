#pragma once
// The level of detail of woven meshes (fabric_table materials with a weave table), chosen once
// per mesh before a render from what the camera sees of it: the weave level (the table modulated
// over the repeat, weave_modulation.h) where one repeat spans at least the material's
// weave_min_pixels pixels at the mesh's nearest point to the camera, the table level elsewhere.
// Both levels have the same mean radiance: the modulation's mean over the repeat is 1.
//
// A pixel's footprint at distance d from a perspective camera, on a surface facing it, is
// 2 d tan(yfov / 2) / height metres (the film's pixels are square: the same as the horizontal
// field of view over the width); an orthographic camera's is 2 half_height / height at any
// distance. d is the distance from the camera to the mesh's bounding box (0 inside it: the weave
// level), whatever the view direction: the choice errs towards the weave level, never blurring a
// repeat the camera could resolve. The repeat's size is the smaller of its two sides, metres.
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/integrators/render_settings.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/render_scene.h"

namespace weft {

// The size of 'repeat_m' metres in pixels at the nearest point of 'box' to the camera, on a film
// 'film_height' pixels high; infinity when the camera is inside the box.
double repeat_pixels(const Camera& camera, int film_height, const Bounds3& box, double repeat_m);

// Whether 'level' at 'pixels' per repeat shades the weave ("auto": at least min_pixels).
bool weave_level_chosen(WeaveLevel level, double pixels, double min_pixels);

struct WeaveLevelChoice {
  std::string object;        // the mesh's name (RenderScene::WovenMesh)
  uint32_t shape = 0;        // the mesh index (SurfaceHit::shape)
  std::string setting;       // the material's level: "auto" | "weave" | "table"
  bool weave = false;        // the level chosen: weave (true) or table
  double repeat_pixels = 0;  // the repeat's size in pixels (infinity: camera inside its box)
  std::string weave_file;    // the weave table
};

// One choice per woven mesh of the scene (RenderScene::woven_meshes order; empty when none).
std::vector<WeaveLevelChoice> choose_weave_levels(const RenderScene& scene, const Camera& camera,
                                                  const RenderSettings& settings);
// The flags RenderScene::with_weave_levels takes.
std::vector<uint8_t> weave_flags(const std::vector<WeaveLevelChoice>& choices);
// As a render's --json reports them: [{"object", "mesh", "level" ("weave" | "table"),
// "setting", "repeat_pixels" (null: the camera is inside the mesh's box), "weave"}].
nlohmann::json weave_levels_json(const std::vector<WeaveLevelChoice>& choices);

}  // namespace weft
