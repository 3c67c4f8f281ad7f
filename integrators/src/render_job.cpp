#include "weft/integrators/render_job.h"

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/integrators/image.h"
#include "weft/integrators/masked_render.h"
#include "weft/scenes/render_scene.h"

namespace weft {
namespace {

void check_output(const std::filesystem::path& p, const std::string& ext, const std::string& what) {
  if (p.extension() != ext) throw Error(p.string(), what, "must end in " + ext);
  const auto dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw Error(p.string(), what, "output directory does not exist");
}

}  // namespace

RenderJobResult render_to_files(const SceneDescription& desc, const RenderJob& job,
                                const ProgressCallback& progress,
                                const FiberTableResolver& fiber_tables) {
  // Everything that can be checked is checked before the (long) render.
  check_output(job.exr, ".exr", "output");
  if (job.png) check_output(*job.png, ".png", "preview");
  if (job.mask) check_output(*job.mask, ".exr", "mask");
  if (!desc.camera) throw Error(desc.source, "camera", "no camera: add 'camera' or a glTF camera");
  const std::vector<uint8_t> mask =
      job.mask ? desc.select_object(job.mask_object) : std::vector<uint8_t>();
  RenderSceneOptions scene_options;
  scene_options.material_progress = progress;
  scene_options.fiber_tables = fiber_tables;
  const RenderScene scene(desc, scene_options);
  RenderResult r;
  std::vector<float> coverage;
  if (job.mask) {
    MaskedRender m = render_masked(scene, *desc.camera, job.settings, mask, progress);
    r = std::move(m.render);
    coverage = std::move(m.coverage);
  } else {
    r = render(scene, *desc.camera, job.settings, progress);
  }
  RenderJobResult out;
  out.rays = r.rays;
  out.nonfinite_samples = r.nonfinite_samples;
  out.cancelled = r.cancelled;
  if (r.cancelled) return out;  // nothing half-finished reaches the disk
  // All or none: a preview that cannot be written leaves no EXR behind.
  std::vector<std::pair<std::filesystem::path, FileWriter>> files{
      {job.exr, [&](const std::filesystem::path& p) { write_exr(p, r.image); }}};
  if (job.png)
    files.emplace_back(*job.png,
                       [&](const std::filesystem::path& p) { write_png_preview(p, r.image); });
  if (job.mask)
    files.emplace_back(*job.mask, [&](const std::filesystem::path& p) {
      write_mask_exr(p, job.settings.width, job.settings.height, coverage);
    });
  write_all_atomically(files);
  return out;
}

}  // namespace weft
