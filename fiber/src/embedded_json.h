#pragma once
// The JSON files compiled into the library (weft_fiber_embed_json in fiber/CMakeLists.txt): the
// presets and the dye spectra. One declaration, included by the generated sources that define
// the arrays and by their readers, so the two cannot disagree.

namespace weft::detail {

struct EmbeddedJson {
  const char* name;
  const char* json;
};

extern const EmbeddedJson kFiberPresets[];  // fiber/presets/*.json
extern const int kNumFiberPresets;
extern const EmbeddedJson kFiberDyes[];  // fiber/data/dyes/*.json
extern const int kNumFiberDyes;

}  // namespace weft::detail
