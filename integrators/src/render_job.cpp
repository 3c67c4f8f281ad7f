#include "weft/integrators/render_job.h"

#include <cmath>
#include <utility>
#include <vector>

#include "image_hdr.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/integrators/image.h"
#include "weft/integrators/masked_render.h"
#include "weft/scenes/render_scene.h"

namespace weft {
namespace {

void check_output(const std::filesystem::path& p, const std::string& ext, const std::string& what) {
  const bool image = what == "output" && (p.extension() == ".png" || p.extension() == ".hdr");
  if (p.extension() != ext && !image)
    throw Error(p.string(), what,
                "must end in " + ext + (what == "output" ? ", .png or .hdr" : ""));
  const auto dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw Error(p.string(), what, "output directory does not exist");
}

}  // namespace

void check_render_outputs(const SceneDescription& desc, const RenderJob& job) {
  std::vector<NamedPath> outputs = {{job.exr, "output"}};
  check_output(job.exr, ".exr", "output");
  if (job.png) check_output(*job.png, ".png", "preview"), outputs.push_back({*job.png, "preview"});
  if (job.mask) check_output(*job.mask, ".exr", "mask"), outputs.push_back({*job.mask, "mask"});
  if (job.albedo)
    check_output(*job.albedo, ".exr", "albedo"), outputs.push_back({*job.albedo, "albedo"});
  if (job.normal)
    check_output(*job.normal, ".exr", "normal"), outputs.push_back({*job.normal, "normal"});
  check_output_paths(outputs, {{desc.source, "scene description"}});
}

RenderJobResult render_to_files(const SceneDescription& desc, const RenderJob& job,
                                const ProgressCallback& progress,
                                const FiberTableResolver& fiber_tables) {
  // Everything that can be checked is checked before the (long) render.
  check_render_outputs(desc, job);
  if (!desc.camera) throw Error(desc.source, "camera", "no camera: add 'camera' or a glTF camera");
  if (job.mask && (job.settings.crop || job.settings.time_limit_s > 0))
    throw Error(job.mask->string(), "mask",
                "a coverage mask is of the whole film and every sample: not with a crop window or "
                "a time limit");
  if (!(job.preview_exposure > 0) || !std::isfinite(job.preview_exposure))
    throw Error("", "exposure", "must give a finite positive scale");
  RenderSettings settings = job.settings;
  settings.aov_albedo = settings.aov_albedo || job.albedo.has_value();
  settings.aov_normal = settings.aov_normal || job.normal.has_value();
  check_crop(settings.crop.value_or(PixelWindow{0, settings.width, 0, settings.height}),
             settings.width, settings.height, desc.source, "render.crop");
  const std::vector<uint8_t> mask =
      job.mask ? desc.select_object(job.mask_object) : std::vector<uint8_t>();
  RenderSceneOptions scene_options;
  scene_options.material_progress = progress;
  scene_options.build_progress = progress;
  scene_options.fiber_tables = fiber_tables;
  const RenderScene scene(desc, scene_options);
  RenderResult r;
  std::vector<float> coverage;
  if (job.mask) {
    MaskedRender m = render_masked(scene, *desc.camera, settings, mask, progress);
    r = std::move(m.render);
    coverage = std::move(m.coverage);
  } else {
    r = render(scene, *desc.camera, settings, progress);
  }
  RenderJobResult out;
  out.rays = r.rays;
  out.nonfinite_samples = r.nonfinite_samples;
  out.cancelled = r.cancelled;
  out.spp_done = r.spp_done;
  out.weave_levels = r.weave_levels;
  if (r.cancelled) return out;  // nothing half-finished reaches the disk
  RenderMetadata meta;
  meta.scene = std::filesystem::path(desc.source).filename().string();
  meta.camera_name = job.camera_name;
  meta.seed = settings.seed;
  meta.spp = r.spp_done;
  meta.spp_requested = settings.spp;
  meta.time_limit_s = settings.time_limit_s;
  meta.camera = *desc.camera;
  if (settings.spectral) meta.pass = "linear sRGB radiance, transported in 33 bands (spectral)";
  RenderMetadata albedo_meta = meta, normal_meta = meta;
  albedo_meta.pass = "albedo";
  normal_meta.pass = "normal (world space, towards the camera)";
  // All or none: a preview or pass that cannot be written leaves no EXR behind. The image goes
  // in the format its name asks for: an EXR with the metadata, an sRGB PNG as the preview, or
  // Radiance RGBE.
  const std::string format = job.exr.extension().string();
  std::vector<std::pair<std::filesystem::path, FileWriter>> files{
      {job.exr, [&](const std::filesystem::path& p) {
         if (format == ".png")
           write_png_preview(p, r.image, job.preview_exposure);
         else if (format == ".hdr")
           write_hdr(p, r.image);
         else
           write_exr(p, r.image, &meta);
       }}};
  if (job.png)
    files.emplace_back(*job.png, [&](const std::filesystem::path& p) {
      write_png_preview(p, r.image, job.preview_exposure);
    });
  if (job.mask)
    files.emplace_back(*job.mask, [&](const std::filesystem::path& p) {
      write_mask_exr(p, settings.width, settings.height, coverage);
    });
  if (job.albedo)
    files.emplace_back(
        *job.albedo, [&](const std::filesystem::path& p) { write_exr(p, r.albedo, &albedo_meta); });
  if (job.normal)
    files.emplace_back(
        *job.normal, [&](const std::filesystem::path& p) { write_exr(p, r.normal, &normal_meta); });
  write_all_atomically(files);
  return out;
}

}  // namespace weft
