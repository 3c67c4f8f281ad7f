#pragma once
// THE output guard: every command checks its outputs here before any work.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/run_limits.h"

namespace weft {

// Each output names a file in an existing directory, no two outputs name the same file, and none
// is any file the job reads: compared by identity (same device and inode, so a symbolic or hard
// link to an input is that input), a not-yet-existing output by its resolved folder and name. An
// output inside an input folder (the bake cache) is refused too. 'folders' are outputs replaced
// whole (verify's report folder, weft slurm's script folder): refused when they hold any input.
// Inputs that are not files (a preset name) are ignored. weft::Error naming the output and the
// input otherwise. The inputs are added to limits.guarded_inputs when it is set.
void validate_output_paths(const RunLimits& limits, const std::vector<NamedPath>& outputs,
                           const std::vector<NamedPath>& inputs,
                           const std::vector<NamedPath>& folders = {});

// Every string in 'j' (values and keys, at any depth) that names an existing file or folder,
// named 'what' for the output guard: the files a part's job or a material's parameters name.
std::vector<NamedPath> json_named_files(const nlohmann::json& j, const std::string& what);

}  // namespace weft
