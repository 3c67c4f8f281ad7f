#pragma once
// A woven sample that is one flat sheet: the simplest geometry the fabric ray trace and its steps
// can be checked on analytically.
#include "weft/scenes/weave.h"

namespace weft::testing {

// A flat sheet (a quad facing +y) filling one repeat of period 1 x 1 mm, 0.1 mm thick slab.
inline WovenSample flat_sheet() {
  WovenSample s;
  TriangleMesh m;
  m.material = "warp";
  const float h = 0.5e-3f;
  m.positions = {-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h};
  m.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  m.tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  m.indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +y
  s.meshes.push_back(m);
  s.summary.period_x_mm = s.summary.period_z_mm = 1;
  s.summary.y_min_mm = -0.05;
  s.summary.y_max_mm = 0.05;
  s.summary.source = "flat sheet";
  s.summary.detail = "yarn";
  return s;
}

}  // namespace weft::testing
