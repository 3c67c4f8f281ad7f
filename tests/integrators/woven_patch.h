#pragma once
// The small woven patch that integrator tests render for inter-reflections: the legacy generator's
// 4 x 4 yarns (32 segments along, 6 sides around), as a description holding its two meshes and
// nothing else; each test adds the materials, lights and camera it needs.
#include <memory>
#include <utility>

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

}  // namespace weft::testing
