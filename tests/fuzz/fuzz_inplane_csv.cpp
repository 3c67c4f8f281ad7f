// Measured in-plane tables (weft verify --measured: the format of
// materials/data/measured/*/inplane.csv), seeded with the bundled ones.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/verify/verify.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)weft::read_measured_inplane(weft::fuzz::input_file(data, size, ".csv"));
  } catch (const weft::Error&) {
  }
  return 0;
}
