#pragma once
// The small woven patch that integrator tests render for inter-reflections: the legacy generator's
// 4 x 4 yarns (32 segments along, 6 sides around), as a description holding its two meshes and
// nothing else; each test adds the materials, lights and camera it needs.
#include <memory>
#include <utility>

#include "weft/core/math.h"
#include "weft/integrators/render_settings.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/weave.h"

namespace weft::testing {

inline SceneDescription woven_patch() {
  WeaveParams p;
  p.yarns = 4, p.segments = 32, p.sides = 6;
  SceneDescription d;
  d.source = "woven";
  for (auto& m : make_weave(p))
    d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(m)));
  return d;
}

// The patch lit for render tests: Lambert warp and weft under a parallel light and an
// environment (which adds MIS paths), seen by an orthographic camera from 20 degrees.
inline SceneDescription lit_woven_patch() {
  SceneDescription d = woven_patch();
  d.materials["warp"] = {"lambert", {{"reflectance", {0.6, 0.15, 0.1}}}, {}, {}, "materials.warp"};
  d.materials["weft"] = {"lambert", {{"reflectance", 0.5}}, {}, {}, "materials.weft"};
  d.lights.directional.push_back({d.frame.direction(deg_to_rad(30), 0), Rgb(1.0)});
  d.lights.environment = Rgb(0.2);
  d.camera = frame_box_orthographic(d.object_bounds(""), d.frame.direction(deg_to_rad(20), kPi),
                                    d.frame.normal);
  return d;
}

// A few samples on a film that is not a multiple of the tile size.
inline RenderSettings small_render_settings(int threads) {
  RenderSettings s;
  s.width = 45;
  s.height = 37;
  s.spp = 3;
  s.seed = 5;
  s.threads = threads;
  return s;
}

}  // namespace weft::testing
