#pragma once
// A weave with warp and weft exchanged, for the tests of the plain weave's 90-degree symmetry
// (scenes/test_woven.cpp on the geometry; tests/ is on the include path: "scenes/swapped_weave.h").
#include <utility>

#include "weft/scenes/weave.h"

namespace weft::testing {

// 'o' with the warp's and the weft's spacing, width and thickness swapped: for a plain weave with
// balanced crimp (warp_crimp_share < 0), 'o' turned by 90 degrees about the normal.
inline WeaveOptions with_warp_and_weft_swapped(WeaveOptions o) {
  std::swap(o.warp_spacing_mm, o.weft_spacing_mm);
  std::swap(o.warp_width_mm, o.weft_width_mm);
  std::swap(o.warp_thickness_mm, o.weft_thickness_mm);
  return o;
}

}  // namespace weft::testing
