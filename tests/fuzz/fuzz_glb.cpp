// Binary glTF (.glb) files as a scene names them.
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/scenes/gltf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    weft::load_gltf(weft::fuzz::input_file(data, size, ".glb"));
  } catch (const weft::Error&) {
  }
  return 0;
}
