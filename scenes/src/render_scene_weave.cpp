// RenderScene's woven meshes: fabric_table materials with a weave table, and which of them are
// shaded at their weave level (render_scene.h).
#include <variant>

#include "weft/core/error.h"
#include "weft/scenes/render_scene.h"

namespace weft {

void RenderScene::find_woven_meshes(const SceneDescription& desc) {
  woven_.clear();
  weave_on_.clear();
  for (size_t i = 0; i < mesh_count(); ++i) {
    SurfaceHit at_mesh;
    at_mesh.shape = static_cast<uint32_t>(i);
    const auto* table = std::get_if<TabulatedBsdf>(&bsdf(at_mesh).variant());
    if (!table || !table->weave) continue;
    const TriangleMesh& mesh = *desc.meshes[i];
    WovenMesh w;
    w.shape = at_mesh.shape;
    w.name = mesh.names.empty() ? "mesh " + std::to_string(i) : mesh.names.front();
    w.weave = table->weave.get();
    if (mesh.uvs.empty() && mesh.triangle_count() > 0) {
      const std::string& field = desc.binding_for(mesh.material).field;
      throw Error(desc.source, field.empty() ? "materials" : field,
                  "mesh '" + w.name +
                      "' has no texture coordinates (UVs): a weave table is placed by them");
    }
    if (desc.mesh_shifts.empty()) w.bounds = mesh.bounds();
    for (const Vec3& s : desc.mesh_shifts) {
      const Bounds3 b = mesh.bounds();
      w.bounds.expand(Bounds3{b.lo + s, b.hi + s});
    }
    woven_.push_back(std::move(w));
  }
  std::vector<uint8_t> on;
  for (const WovenMesh& w : woven_) on.push_back(w.weave->level == WeaveLevel::weave);
  *this = with_weave_levels(on);
}

bool RenderScene::weave_level(size_t k) const {
  return !weave_on_.empty() && weave_on_[woven_.at(k).shape] != nullptr;
}

RenderScene RenderScene::with_weave_levels(const std::vector<uint8_t>& weave_on) const {
  if (weave_on.size() != woven_.size())
    throw Error("", "weave_on",
                std::to_string(weave_on.size()) + " flags for " + std::to_string(woven_.size()) +
                    " woven meshes");
  RenderScene r = *this;
  r.weave_on_.clear();
  for (size_t k = 0; k < woven_.size(); ++k) {
    if (!weave_on[k]) continue;
    if (r.weave_on_.empty()) r.weave_on_.assign(mesh_count(), nullptr);
    r.weave_on_[woven_[k].shape] = woven_[k].weave;
  }
  return r;
}

}  // namespace weft
