// The renders of weft verify's report (paper's Figs. 8-9): a flat patch of cloth with each model's
// fabric table, lit from the viewer's side and from behind, through the one renderer (a scene
// description built in memory, RenderScene, render) as `weft render` would draw it.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_settings.h"
#include "weft/materials/table_cache.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/primitives.h"
#include "weft/scenes/render_scene.h"
#include "weft/verify/verify.h"

namespace weft {

namespace {

// A model's material as a description's binding under 'key'.
MaterialBinding binding_of(const nlohmann::json& material, const std::string& key) {
  MaterialBinding b;
  b.type = material.at("type").get<std::string>();
  b.params = material.value("params", nlohmann::json::object());
  b.field = "materials." + key;
  return b;
}

}  // namespace

SceneDescription verify_render_scene(const nlohmann::json& material, bool transmission,
                                     const VerifySettings& s,
                                     const std::filesystem::path& base_dir) {
  SceneDescription d;
  d.source = std::string("verify render ") + (transmission ? "transmission" : "reflection");
  d.base_dir = base_dir;
  // glTF's Y up (the description's default frame): the patch lies in the x-z plane, its tangent
  // (the warp, the tables' x axis) along x.
  TriangleMesh cloth = make_quad({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, 1, 1);
  cloth.material = "cloth";
  cloth.names = {"cloth"};
  d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(cloth)));
  d.materials["cloth"] = binding_of(material, "cloth");
  DirectionalLight light;
  light.irradiance = Rgb(kVerifyRenderIrradiance);
  light.to_light = d.frame.direction(deg_to_rad(transmission ? 180.0 : 0.0), deg_to_rad(0.0));
  d.lights.directional.push_back(light);
  // The camera frames the patch from zenith kVerifyRenderViewZenithDeg, azimuth 180 deg.
  d.camera = frame_box_orthographic(
      d.object_bounds("cloth"),
      d.frame.direction(deg_to_rad(kVerifyRenderViewZenithDeg), deg_to_rad(180.0)),
      d.frame.tangent);
  d.render = nlohmann::json{
      {"width", s.render_size}, {"height", s.render_size}, {"spp", s.render_spp}, {"seed", s.seed}};
  return d;
}

VerifyWeaveFrame verify_weave_frame(const WeaveSummary& sample, int size) {
  const double px_mm = sample.period_x_mm, pz_mm = sample.period_z_mm;
  if (!(px_mm > 0 && pz_mm > 0 && std::isfinite(px_mm) && std::isfinite(pz_mm)))
    throw Error("", "sample", "the woven sample has no period");
  if (size < 1) throw Error("", "weave_render_size", "must be >= 1");
  const double cos_view = std::cos(deg_to_rad(kVerifyRenderViewZenithDeg));
  VerifyWeaveFrame f;
  // The film's width runs along z (the weft direction, across the warps), its height along the
  // warp x, foreshortened by the view's cosine.
  f.repeats_z = std::max(1, static_cast<int>(std::lround(kVerifyWeaveFrameMm / pz_mm)));
  f.repeats_x =
      std::max(1, static_cast<int>(std::lround(kVerifyWeaveFrameMm / (px_mm * cos_view))));
  const double width_m = f.repeats_z * pz_mm * 1e-3,
               height_m = f.repeats_x * px_mm * cos_view * 1e-3;
  f.half_width_m = width_m / 2;
  f.half_height_m = height_m / 2;
  if (width_m >= height_m) {
    f.width = size;
    f.height = std::max(1, static_cast<int>(std::lround(size * height_m / width_m)));
  } else {
    f.height = size;
    f.width = std::max(1, static_cast<int>(std::lround(size * width_m / height_m)));
  }
  // At least a repeat of cloth past the film's edges on every side (the thickness's parallax at
  // 30 deg, tan 30 deg times half the thickness, is well within a repeat for woven cloth).
  f.copies_x = f.repeats_x / 2 + 1;
  f.copies_z = f.repeats_z / 2 + 1;
  return f;
}

std::optional<SceneDescription> verify_weave_scene(const WovenSample& sample,
                                                   const nlohmann::json& material,
                                                   const VerifySettings& s,
                                                   const std::filesystem::path& base_dir,
                                                   const ProgressCallback& progress) {
  if (sample.fibers.curve_count() == 0)
    throw Error("", "sample", "the fiber-level render needs the woven sample at fiber detail");
  const VerifyWeaveFrame f = verify_weave_frame(sample.summary, s.weave_render_size);
  const std::string source = "verify weave render";
  // Made in place rather than parsed: the description parser wants its geometry from glTF files
  // or inline objects, and the fibers are the tiled sample's.
  std::optional<SceneDescription> tiled =
      tiled_woven_description(sample, f.copies_x, f.copies_z, source, false, progress);
  if (!tiled) return std::nullopt;
  SceneDescription d = std::move(*tiled);
  d.base_dir = base_dir;
  for (const char* key : {"warp", "weft"}) d.materials[key] = binding_of(material, key);
  // glTF's frame (weave.h): the cloth's normal is +y, the warp +x. The lights as the patch's:
  // the first on the viewer's side (reflection), the second behind the cloth (transmission).
  for (const double side : {1.0, -1.0}) {
    DirectionalLight light;
    light.to_light = {0, side, 0};
    light.irradiance = Rgb(kVerifyRenderIrradiance);
    d.lights.directional.push_back(light);
  }
  // Towards the viewer: zenith v from the normal, azimuth 180 deg from the warp, as the patch's
  // camera; the film's centre looks at the sample's centre. A film 1 cm away lies outside the
  // cloth (a fraction of a millimetre thick).
  const double v = deg_to_rad(kVerifyRenderViewZenithDeg), distance_m = 0.01;
  Camera cam =
      Camera::look_at(Camera::Type::orthographic, Vec3{-std::sin(v), std::cos(v), 0} * distance_m,
                      {0, 0, 0}, {0, 1, 0});
  cam.half_width = f.half_width_m;
  cam.half_height = f.half_height_m;
  d.camera = cam;
  d.render = nlohmann::json{
      {"width", f.width}, {"height", f.height}, {"spp", s.weave_render_spp}, {"seed", s.seed}};
  return d;
}

namespace {

const char* configuration_name(bool transmission) {
  return transmission ? "transmission" : "reflection";
}

// Renders a description as `weft render` would, refusing non-finite samples. The scene build and
// the render poll 'progress' as `weft render`'s do (a publication render of a large sample takes
// minutes); nothing when it said stop.
// 'tables' is shared by the report's renders, so a table two of them read is prepared once.
// With 'light_groups' the images are each light's (RenderResult::light_images), else the one.
std::optional<std::vector<Image>> render_description(const SceneDescription& desc,
                                                     const VerifySettings& s,
                                                     const ProgressCallback& progress,
                                                     const std::shared_ptr<TableCache>& tables,
                                                     bool light_groups = false) {
  RenderSceneOptions options;
  options.table_cache = tables;
  options.material_progress = progress;
  options.build_progress = progress;
  const RenderScene scene(desc, options);
  if (scene.cancelled()) return std::nullopt;
  RenderSettings rs = render_settings_from(desc);
  rs.threads = s.threads;  // not a description's setting; the image does not depend on it
  rs.light_groups = light_groups;
  RenderResult r = render(scene, *desc.camera, rs, progress);
  if (r.cancelled) return std::nullopt;
  if (r.nonfinite_samples > 0)
    throw Error(desc.source, "render", std::to_string(r.nonfinite_samples) + " non-finite samples");
  if (light_groups) return std::move(r.light_images);
  return std::vector<Image>{std::move(r.image)};
}

Rgb mean_of(const Image& image, int x0, int x1, int y0, int y1) {
  Rgb sum;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x, ++n) sum += image.at(x, y);
  return sum / static_cast<double>(std::max(1, n));
}

// Nothing when 'progress' said stop.
std::optional<VerifyRender> render_one(const std::filesystem::path& folder,
                                       const nlohmann::json& material, const std::string& model,
                                       const std::string& label, bool transmission,
                                       const VerifySettings& s, const ProgressCallback& progress,
                                       const std::shared_ptr<TableCache>& tables) {
  const std::string config = configuration_name(transmission);
  const std::string source = "verify render " + config + " " + model;
  VerifyRender v;
  v.kind = "patch";
  v.model = model;
  v.configuration = config;
  v.stem = "render-" + config + "-" + model;
  SceneDescription desc = verify_render_scene(material, transmission, s, folder);
  desc.source = source;
  std::optional<std::vector<Image>> images = render_description(desc, s, progress, tables);
  if (!images) return std::nullopt;
  v.image = std::move(images->front());
  // The central half of the film lies inside the patch (the film is the patch's projection).
  const int w = v.image.width, h = v.image.height;
  v.patch_radiance = mean_of(v.image, w / 4, w - w / 4, h / 4, h - h / 4);
  v.mean = mean_of(v.image, 0, w, 0, h);
  v.caption = label + ", " +
              (transmission ? "transmission: light from behind the cloth"
                            : "reflection: light on the viewer's side") +
              ", at normal incidence; orthographic view at " +
              std::to_string(static_cast<int>(kVerifyRenderViewZenithDeg)) +
              " deg from the normal; " + std::to_string(s.render_spp) + " spp";
  return v;
}

// Reflection and transmission from one pass of the paths (light groups: each image has the bits
// of a render lit by its light alone); nothing when 'progress' said stop.
std::optional<std::vector<VerifyRender>> render_weave(
    const WovenSample& sample, const std::filesystem::path& folder, const std::string& fiber_file,
    const std::string& model, const std::string& label, bool spectral, const VerifySettings& s,
    const ProgressCallback& progress, const std::shared_ptr<TableCache>& tables) {
  // Read by cell, as the ray trace reads it: the image's mean is then the ray-traced fabric
  // table's value for this view and light (TableLookup).
  const nlohmann::json material = {{"type", "fiber_table"},
                                   {"params", {{"file", fiber_file}, {"interpolation", "cell"}}}};
  std::optional<SceneDescription> tiled = verify_weave_scene(sample, material, s, folder, progress);
  if (!tiled) return std::nullopt;
  SceneDescription& desc = *tiled;
  // A spectral fiber table is rendered band by band, as the ray trace traces it: light that
  // scatters many times in a coloured fiber is not the RGB transport of the reduced table.
  (*desc.render)["spectral"] = spectral;
  std::optional<std::vector<Image>> images = render_description(desc, s, progress, tables, true);
  if (!images) return std::nullopt;
  const VerifyWeaveFrame f = verify_weave_frame(sample.summary, s.weave_render_size);
  std::vector<VerifyRender> out;
  for (const bool transmission : {false, true}) {
    VerifyRender& v = out.emplace_back();
    v.kind = "weave";
    v.model = model;
    v.configuration = configuration_name(transmission);
    v.stem = "render-weave-" + v.configuration + "-" + model;
    v.image = std::move((*images)[transmission ? 1 : 0]);
    v.mean = mean_of(v.image, 0, v.image.width, 0, v.image.height);
    v.patch_radiance = v.mean;
    v.caption = label + " on every fiber of the woven sample, " +
                (transmission ? "transmission: light from behind the cloth"
                              : "reflection: light on the viewer's side") +
                ", at normal incidence; orthographic view at " +
                std::to_string(static_cast<int>(kVerifyRenderViewZenithDeg)) +
                " deg from the normal, the film " + std::to_string(f.repeats_z) +
                " repeats across the warps by " + std::to_string(f.repeats_x) + " along them; " +
                std::to_string(s.weave_render_spp) + " spp" +
                (spectral ? ", light transported in 33 bands" : ", light transported in RGB");
  }
  return out;
}

}  // namespace

std::vector<VerifyRender> render_verify_samples(const std::filesystem::path& folder,
                                                const VerifyReport& report,
                                                const ProgressCallback& progress, bool* cancelled) {
  std::vector<VerifyRender> out;
  const VerifySettings& s = report.settings;
  const auto tables = std::make_shared<TableCache>();
  // Keeps a render; false (the renders end there) when it was stopped.
  const auto keep = [&](std::optional<VerifyRender> v) {
    if (v) out.push_back(std::move(*v));
    if (!v && cancelled) *cancelled = true;
    return v.has_value();
  };
  struct Table {
    const std::optional<TabulatedBsdfTable>* table;
    const char* model;
    const char* label;
  };
  for (const Table& t :
       {Table{&report.computed_fabric, "computed", "computed fabric (fiber-level ray trace)"},
        Table{&report.classic_fabric, "classic", "classic fiber (Lambert + Cook-Torrance)"}}) {
    if (!*t.table) continue;
    const std::string file = std::string("fabric-") + t.model + ".exr";
    TabulatedBsdfTable rgb = table_to_rgb(**t.table);
    // A renderer's BSDF cannot be negative: the render (a picture, not a figure) shows the
    // table's colours outside the sRGB gamut with their negative components at 0, as the
    // renderer does for any spectral table (materials/tabulated_bsdf.cpp). The metrics keep them.
    for (float& v : rgb.values) v = std::max(v, 0.0f);
    rgb.kind = "fabric";
    rgb.write_exr(folder / file);
    const nlohmann::json material = {{"type", "fabric_table"}, {"params", {{"file", file}}}};
    for (bool transmission : {false, true})
      if (!keep(render_one(folder, material, t.model, t.label, transmission, s, progress, tables)))
        return out;
  }
  // The fibers with each model's fiber table, where the report holds the sample at fiber detail.
  if (report.sample && report.sample->fibers.curve_count() > 0) {
    struct Fiber {
      const std::optional<TabulatedBsdfTable>* table;
      const char* model;
      const char* label;
    };
    for (const Fiber& t : {Fiber{&report.computed_fiber, "computed", "computed fiber table"},
                           Fiber{&report.classic_fiber, "classic",
                                 "classic fiber table (Lambert + Cook-Torrance)"}}) {
      if (!*t.table) continue;
      // The table as the model has it: spectral for the computed fiber (rendered in bands), RGB
      // for the classic one.
      const std::string file = std::string("fiber-") + t.model + ".exr";
      TabulatedBsdfTable table = **t.table;
      table.kind = "fiber";
      table.write_exr(folder / file);
      const bool spectral = table.channels == kNumBands;
      std::optional<std::vector<VerifyRender>> both = render_weave(
          *report.sample, folder, file, t.model, t.label, spectral, s, progress, tables);
      if (!both) {
        if (cancelled) *cancelled = true;
        return out;
      }
      for (VerifyRender& v : *both) out.push_back(std::move(v));
    }
  }
  // The measurement is of reflection only.
  if (!report.measured_nbrdf.empty()) {
    const nlohmann::json material = {
        {"type", "measured_nbrdf"},
        {"params", {{"file", std::filesystem::absolute(report.measured_nbrdf).string()}}}};
    keep(render_one(folder, material, "measured", "measured BRDF (neural fit of the measurement)",
                    false, s, progress, tables));
  }
  return out;
}

}  // namespace weft
