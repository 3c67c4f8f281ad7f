#pragma once
// What the tests of woven samples share: the bundled WIF drafts, the message with which a sample
// is refused, and a description with every shape bound to Lambert (a RenderScene needs a material;
// the geometry is what is tested).
#include <filesystem>
#include <string>

#include "test_util.h"
#include "weft/scenes/description.h"
#include "weft/scenes/weave.h"

namespace weft::testing {

inline const std::filesystem::path kWifDir =
    std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/data/wif";

// The message with which making a woven sample of these options fails ("" if it does not).
inline std::string woven_sample_error(const WeaveOptions& o) {
  return error_of([&] { make_woven_sample(o); });
}

inline SceneDescription all_lambert(SceneDescription d) {
  MaterialBinding any;
  any.type = "lambert";
  d.default_material = any;
  return d;
}

}  // namespace weft::testing
