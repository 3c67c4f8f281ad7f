// Measured material data (materials/data/measured: the NBRDF weights a measured_nbrdf material
// loads; seeded also with the in-plane CSVs beside them).
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/materials/measured_nbrdf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto net = weft::NbrdfNetwork::load(weft::fuzz::input_file(data, size, ".txt"));
    net.eval_upper({0, 0, 1}, {0.6, 0, 0.8});
  } catch (const weft::Error&) {
  }
  return 0;
}
