#pragma once
// A whole render: scene description in, image files out. Outputs are checked before rendering and
// written atomically after it; a cancelled render writes nothing.
#include <filesystem>
#include <optional>
#include <string>

#include "weft/core/progress.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/registry.h"
#include "weft/scenes/description.h"

namespace weft {

struct RenderJob {
  std::filesystem::path exr;                  // required, .exr
  std::optional<std::filesystem::path> png;   // sRGB preview, .png
  std::optional<std::filesystem::path> mask;  // coverage of mask_object, .exr
  std::string mask_object;
  RenderSettings settings;
};

using RenderJobResult = RenderOutcome;  // a cancelled job wrote nothing

// 'fiber_tables' makes the fiber tables that materials name by spec (null: such materials are an
// error).
RenderJobResult render_to_files(const SceneDescription& desc, const RenderJob& job,
                                const ProgressCallback& progress = no_progress(),
                                const FiberTableResolver& fiber_tables = {});

}  // namespace weft
