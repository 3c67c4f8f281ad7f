// Part and checkpoint files of sharded or resumed runs (`weft merge`, `--resume`): read, and
// merged with themselves (the header's counts decide what merging allocates).
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/core/job_part.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto path = weft::fuzz::input_file(data, size, ".part");
    weft::read_job_part(path);
    weft::merge_job_parts({path});
  } catch (const weft::Error&) {
  }
  return 0;
}
