#pragma once
// A whole render: scene description in, image files out. Outputs are checked before rendering and
// written atomically after it; a cancelled render writes nothing. Every EXR carries the render's
// metadata (image.h RenderMetadata) and is the same bytes for the same inputs.
#include <filesystem>
#include <optional>
#include <string>

#include "weft/core/progress.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/registry.h"
#include "weft/scenes/description.h"

namespace weft {

struct RenderJob {
  std::filesystem::path exr;  // required: .exr; or .png (as the preview) or .hdr (Radiance RGBE)
  std::optional<std::filesystem::path> png;   // sRGB preview, .png
  std::optional<std::filesystem::path> mask;  // coverage of mask_object, .exr
  std::string mask_object;
  // Passes of the first surface seen (RenderResult::albedo, normal), each its own RGB .exr with
  // the metadata of the image (a denoiser's auxiliary inputs).
  std::optional<std::filesystem::path> albedo, normal;
  RenderSettings settings;
  double preview_exposure = 1;  // the PNG's linear values are multiplied by this
  std::string camera_name;      // as chosen on the command line, for the metadata
};

// A cancelled job wrote nothing; a time-limited one wrote spp_done samples per pixel.
struct RenderJobResult : RenderOutcome {
  int spp_done = 0;
  std::vector<WeaveLevelChoice> weave_levels;  // RenderResult::weave_levels
};

// Every output's file name: the required extension, an existing folder, no two outputs the same
// file and none the scene description itself. Error naming the output otherwise.
void check_render_outputs(const SceneDescription& desc, const RenderJob& job);

// 'fiber_tables' makes the fiber tables that materials name by spec (null: such materials are an
// error).
RenderJobResult render_to_files(const SceneDescription& desc, const RenderJob& job,
                                const ProgressCallback& progress = no_progress(),
                                const FiberTableResolver& fiber_tables = {});

}  // namespace weft
