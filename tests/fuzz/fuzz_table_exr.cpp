// BSDF tables (.exr, fiber and fabric): read, validate, and prepare for rendering.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/tabulated_bsdf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto t = weft::TabulatedBsdfTable::read_exr(weft::fuzz::input_file(data, size, ".exr"));
    weft::TabulatedBsdfData::prepare(t);
  } catch (const weft::Error&) {
  }
  return 0;
}
