// Fiber spec JSON (`weft bake fiber SPEC`): parse and hash as the bake cache does.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/fiber/fiber_spec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const weft::FiberSpec spec =
        weft::parse_fiber_spec(std::string(weft::fuzz::text(data, size)), "fuzz.json");
    weft::fiber_spec_hash(spec);
  } catch (const weft::Error&) {
  }
  return 0;
}
