// Scene description JSON: parse, bind glTF (relative to scenes/examples, so the seeds' glTF files
// load), and read the render and sweep settings as `weft render` and `weft sweep` do.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/integrators/gonio.h"
#include "weft/integrators/render_settings.h"
#include "weft/scenes/description.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const nlohmann::json j = weft::parse_json(weft::fuzz::text(data, size), "fuzz.json");
    const weft::SceneDescription d = weft::parse_scene_description(
        j, std::filesystem::path(WEFT_SOURCE_DIR) / "scenes" / "examples", "fuzz.json");
    weft::render_settings_from(d);
    if (d.sweep) weft::gonio_settings_from(d);
  } catch (const weft::Error&) {
  }
  return 0;
}
