// WIF weaving drafts (`weft weave --wif`): parse and build the interlacing matrix.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/scenes/wif.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    weft::parse_wif(weft::fuzz::text(data, size), "fuzz.wif").interlacing();
  } catch (const weft::Error&) {
  }
  return 0;
}
