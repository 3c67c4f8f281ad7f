// The renders of weft verify's report (paper's Figs. 8-9): a flat patch of cloth with each model's
// fabric table, lit from the viewer's side and from behind, through the one renderer (a scene
// description in memory, RenderScene, render) as `weft render` would draw it.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_settings.h"
#include "weft/integrators/verify.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

namespace weft {

nlohmann::json verify_render_scene(const nlohmann::json& material, bool transmission,
                                   const VerifySettings& s) {
  using nlohmann::json;
  // glTF's Y up (the description's default frame): the patch lies in the x-z plane, its tangent
  // (the warp, the tables' x axis) along x.
  return json{{"objects", json::array({{{"type", "quad"},
                                        {"name", "cloth"},
                                        {"material", "cloth"},
                                        {"center", {0, 0, 0}},
                                        {"normal", {0, 1, 0}},
                                        {"tangent", {1, 0, 0}},
                                        {"size", {1, 1}}}})},
              {"materials", {{"cloth", material}}},
              {"lights", json::array({{{"type", "parallel"},
                                       {"irradiance", kVerifyRenderIrradiance},
                                       {"zenith_deg", transmission ? 180.0 : 0.0},
                                       {"azimuth_deg", 0.0}}})},
              {"camera",
               {{"type", "orthographic"},
                {"frame_object", "cloth"},
                {"zenith_deg", kVerifyRenderViewZenithDeg},
                {"azimuth_deg", 180.0}}},
              {"render",
               {{"width", s.render_size},
                {"height", s.render_size},
                {"spp", s.render_spp},
                {"seed", s.seed}}}};
}

namespace {

VerifyRender render_one(const std::filesystem::path& folder, const nlohmann::json& material,
                        const std::string& model, const std::string& label, bool transmission,
                        const VerifySettings& s) {
  const std::string config = transmission ? "transmission" : "reflection";
  const std::string source = "verify render " + config + " " + model;
  const SceneDescription desc =
      parse_scene_description(verify_render_scene(material, transmission, s), folder, source);
  const RenderScene scene(desc);
  RenderSettings rs = render_settings_from(desc);
  rs.threads = s.threads;  // not a description's setting; the image does not depend on it
  const RenderResult r = render(scene, *desc.camera, rs);
  if (r.nonfinite_samples > 0)
    throw Error(source, "render", std::to_string(r.nonfinite_samples) + " non-finite samples");
  VerifyRender v;
  v.model = model;
  v.configuration = config;
  v.stem = "render-" + config + "-" + model;
  v.image = r.image;
  // The central half of the film lies inside the patch (the film is the patch's projection).
  const int w = v.image.width, h = v.image.height;
  Rgb sum;
  int n = 0;
  for (int y = h / 4; y < h - h / 4; ++y)
    for (int x = w / 4; x < w - w / 4; ++x, ++n) sum += v.image.at(x, y);
  v.patch_radiance = sum / static_cast<double>(std::max(1, n));
  v.caption = label + ", " +
              (transmission ? "transmission: light from behind the cloth"
                            : "reflection: light on the viewer's side") +
              ", at normal incidence; orthographic view at " +
              std::to_string(static_cast<int>(kVerifyRenderViewZenithDeg)) +
              " deg from the normal; " + std::to_string(s.render_spp) + " spp";
  return v;
}

}  // namespace

std::vector<VerifyRender> render_verify_samples(const std::filesystem::path& folder,
                                                const VerifyReport& report) {
  std::vector<VerifyRender> out;
  const VerifySettings& s = report.settings;
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
    rgb.kind = "fabric";
    rgb.write_exr(folder / file);
    const nlohmann::json material = {{"type", "fabric_table"}, {"params", {{"file", file}}}};
    for (bool transmission : {false, true})
      out.push_back(render_one(folder, material, t.model, t.label, transmission, s));
  }
  // The measurement is of reflection only.
  if (!report.measured_nbrdf.empty()) {
    const nlohmann::json material = {
        {"type", "measured_nbrdf"},
        {"params", {{"file", std::filesystem::absolute(report.measured_nbrdf).string()}}}};
    out.push_back(render_one(folder, material, "measured",
                             "measured BRDF (neural fit of the measurement)", false, s));
  }
  return out;
}

}  // namespace weft
