#pragma once
// What the tests that trace woven samples share: the bundled WIF drafts, and a description with
// every shape bound to Lambert (a RenderScene needs a material; the geometry is what is tested).
#include <filesystem>

#include "weft/scenes/description.h"

namespace weft::testing {

inline const std::filesystem::path kWifDir =
    std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/data/wif";

inline SceneDescription all_lambert(SceneDescription d) {
  MaterialBinding any;
  any.type = "lambert";
  d.default_material = any;
  return d;
}

}  // namespace weft::testing
