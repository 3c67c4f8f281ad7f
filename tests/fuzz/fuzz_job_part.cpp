// Part and checkpoint files of sharded or resumed runs (`weft merge`, `--resume`): read, and
// merged with themselves (the header's counts decide what merging allocates); a ray-traced fabric
// job's parts are then assembled into its table as `weft merge` does (the job's resolution,
// channels and weave decide what that allocates).
#include "fuzz_input.h"
#include "weft/core/error.h"
#include "weft/core/job_part.h"
#include "weft/fabric/fabric_parts.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto path = weft::fuzz::input_file(data, size, ".part");
    const weft::JobPart part = weft::read_job_part(path);
    weft::merge_job_parts({path});
    if (part.command == "bake fabric") weft::assemble_fabric_job(part);
  } catch (const weft::Error&) {
  }
  return 0;
}
