// Woven-sample options JSON (`weft weave --options`, `weft bake fabric --weave`): read them as
// read_weave_options does (relative WIF paths resolve under scenes/data/wif).
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/scenes/weave.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const nlohmann::json j = weft::parse_json(weft::fuzz::text(data, size), "fuzz.json");
    weft::ParamReader r(j, "fuzz.json", "");
    weft::read_weave_options(r, std::filesystem::path(WEFT_SOURCE_DIR) / "scenes" / "data" / "wif");
  } catch (const weft::Error&) {
  }
  return 0;
}
