#include "weft/integrators/render_request.h"

#include <cmath>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"
#include "weft/integrators/render_settings.h"

namespace weft {
namespace {

// "--crop x0,x1,y0,y1": four whole pixel numbers.
PixelWindow parse_render_crop(const std::string& text) {
  std::vector<int> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    const auto n = finite_number(part);
    if (!n || *n != std::floor(*n) || *n < 0 || *n > 16384)
      throw Error("", "--crop", "'" + part + "' is not a pixel number (0 to 16384)");
    v.push_back(static_cast<int>(*n));
  }
  if (v.size() != 4) throw Error("", "--crop", "must be x0,x1,y0,y1, got '" + text + "'");
  return {v[0], v[1], v[2], v[3]};
}

// "OUT.exr" -> "OUT.<pass>.exr".
std::filesystem::path render_pass_path(const std::filesystem::path& exr, const std::string& pass) {
  std::filesystem::path p = exr;
  p.replace_extension("." + pass + ".exr");
  return p;
}

// The job's files and passes, and the camera chosen, from the request.
void set_render_outputs(const RenderRequest& q, SceneDescription& desc, RenderJob& job) {
  job.exr = q.output;
  if (!q.preview.empty()) job.png = q.preview;
  if (!q.mask.empty()) job.mask = q.mask;
  job.mask_object = q.mask_object;
  if (!q.aov.empty()) {
    std::stringstream ss(q.aov);
    std::string pass;
    while (std::getline(ss, pass, ',')) {
      if (pass == "albedo")
        job.albedo = render_pass_path(job.exr, pass);
      else if (pass == "normal")
        job.normal = render_pass_path(job.exr, pass);
      else
        throw Error("", "--aov", "unknown pass '" + pass + "' (valid: albedo, normal)");
    }
  }
  if (!q.camera.empty()) {
    const NamedCamera c = select_camera(desc, q.camera);
    desc.camera = c.camera;
    job.camera_name = c.name.empty() ? "glTF camera " + q.camera : c.name;
  }
}

// The scene's render settings with the request's over them.
RenderSettings requested_render_settings(const RenderRequest& q, const SceneDescription& desc) {
  RenderSettings s = render_settings_from(desc);
  if (q.spp) s.spp = *q.spp;
  if (q.width) s.width = *q.width;
  if (q.height) s.height = *q.height;
  if (q.max_depth) s.max_depth = *q.max_depth;
  if (q.seed) s.seed = *q.seed;
  if (q.spectral) s.spectral = true;
  if (q.time_limit_s) s.time_limit_s = *q.time_limit_s;
  if (!q.crop.empty()) {
    s.crop = parse_render_crop(q.crop);
    check_crop(*s.crop, s.width, s.height, "", "--crop");
  }
  s.threads = q.threads;
  return s;
}

// Every output against the inputs, then memory and time.
void check_render_resources(const RenderRequest& q, const RenderPlan& plan) {
  const RenderJob& job = plan.job;
  std::vector<NamedPath> outputs = {{job.exr, "--output"}};
  if (job.png) outputs.push_back({*job.png, "--preview"});
  if (job.mask) outputs.push_back({*job.mask, "--mask"});
  if (job.albedo) outputs.push_back({*job.albedo, "--aov albedo"});
  if (job.normal) outputs.push_back({*job.normal, "--aov normal"});
  validate_output_paths(q.limits, outputs, plan.inputs);
  const RenderSettings& s = job.settings;
  RenderSettings sized = s;  // with the passes the job writes (render_job turns them on)
  sized.aov_albedo = sized.aov_albedo || job.albedo.has_value();
  sized.aov_normal = sized.aov_normal || job.normal.has_value();
  check_memory(q.limits, render_bytes(sized, job.png.has_value(), job.mask.has_value()), q.scene,
               "width x height",
               "a " + std::to_string(s.width) + " x " + std::to_string(s.height) + " render" +
                   (job.mask ? " with a mask" : ""));
  // A time limit bounds the work itself.
  if (s.time_limit_s > 0) return;
  const auto& c = s.crop;
  const double pixels = c ? double(c->width()) * c->height() : double(s.width) * s.height;
  check_long_work(q.limits, pixels * s.spp, kMinSecondsPerPathSample, s.threads, q.scene, "spp",
                  "a render of " + std::to_string(int64_t(pixels)) + " pixels at " +
                      std::to_string(s.spp) + " spp",
                  "0.05 us per path sample per core at least");
}

}  // namespace

RenderPlan plan_render(const RenderRequest& q, const ScenePlanHooks& hooks) {
  if (!q.mask.empty() && q.mask_object.empty())
    throw Error("", "--mask-object", "is required with --mask");
  std::vector<SceneOverride> overrides;
  for (const auto& d : q.defines) overrides.push_back(parse_scene_override(d));
  RenderPlan plan;
  plan.description = load_scene_description(q.scene, overrides);
  hooks.scene_loaded(plan.description);
  set_render_outputs(q, plan.description, plan.job);
  plan.job.preview_exposure = std::exp2(q.exposure_ev);
  // Only an 8-bit preview is exposed; an EXR or HDR keeps the linear values.
  if (q.exposure_ev != 0 && !plan.job.png && plan.job.exr.extension() != ".png")
    hooks.warning(
        "--exposure does nothing here: it applies to a PNG (--preview, or an output "
        "ending in .png), and " +
        plan.job.exr.string() + " keeps the linear values");
  plan.job.settings = requested_render_settings(q, plan.description);
  plan.inputs = scene_inputs(q.scene, plan.description);
  check_render_resources(q, plan);
  return plan;
}

}  // namespace weft
