#include "weft/scenes/render_scene.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

#include "weft/core/error.h"
#include "weft/materials/registry.h"

namespace weft {

namespace {
struct EmbreeErrors {
  std::mutex mutex;
  std::string message;
};
}  // namespace

struct RenderScene::Geometry {
  struct MeshRecord {
    std::shared_ptr<const TriangleMesh> mesh;
    uint32_t bsdf = 0;
    bool emits = false;  // part of the area light
  };
  EmbreeErrors errors;  // outlives the device, which reports into it
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<MeshRecord> meshes;
  std::vector<Bsdf> bsdfs;
  AreaLight area_light;  // the emissive triangles
  Bounds3 bounds;
  size_t triangles = 0;

  ~Geometry() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void on_embree_error(void* user, RTCError code, const char* str) {
  auto* e = static_cast<EmbreeErrors*>(user);
  std::lock_guard lock(e->mutex);
  if (e->message.empty())
    e->message = "Embree error " + std::to_string(code) + ": " + (str ? str : "");
}

Vec3 vertex(const TriangleMesh& m, uint32_t i) {
  return m.position(i);
}

// An Embree ray query for 'ray' (single precision, no hit yet).
RTCRayHit embree_ray(const Ray& ray) {
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(ray.o.x);
  rh.ray.org_y = static_cast<float>(ray.o.y);
  rh.ray.org_z = static_cast<float>(ray.o.z);
  rh.ray.dir_x = static_cast<float>(ray.d.x);
  rh.ray.dir_y = static_cast<float>(ray.d.y);
  rh.ray.dir_z = static_cast<float>(ray.d.z);
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = ray.tmax > 3e38 ? INFINITY : static_cast<float>(ray.tmax);
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.time = 0.0f;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

}  // namespace

RenderScene::RenderScene(const SceneDescription& desc, const RenderSceneOptions& options) {
  auto geo = std::make_shared<Geometry>();
  EmbreeErrors& errors = geo->errors;
  geo->device = rtcNewDevice(nullptr);
  if (!geo->device) throw Error(desc.source, "", "cannot create the Embree device");
  rtcSetDeviceErrorFunction(geo->device, on_embree_error, &errors);
  geo->scene = rtcNewScene(geo->device);
  rtcSetSceneFlags(geo->scene, RTC_SCENE_FLAG_ROBUST);  // watertight: no leaks along shared edges
  rtcSetSceneBuildQuality(geo->scene, RTC_BUILD_QUALITY_HIGH);

  if (!options.override_meshes.empty() && options.override_meshes.size() != desc.meshes.size())
    throw Error(desc.source, "", "override mask does not match the mesh count");
  // One BSDF per binding, created once and shared by every mesh that uses it.
  std::map<const MaterialBinding*, uint32_t> bsdf_of;
  const auto cache = options.table_cache ? options.table_cache : std::make_shared<TableCache>();
  auto bsdf_index = [&](const MaterialBinding& b) {
    const auto it = bsdf_of.find(&b);
    if (it != bsdf_of.end()) return it->second;
    MaterialContext ctx;
    ctx.base_dir = desc.base_dir;
    ctx.source_file = desc.source;
    ctx.field_prefix = b.field.empty() ? "materials" : b.field + ".params";
    ctx.cache = cache;
    ctx.progress = options.material_progress;
    ctx.fiber_tables = options.fiber_tables;
    geo->bsdfs.push_back(make_bsdf(b.type, b.params, ctx));
    const auto id = static_cast<uint32_t>(geo->bsdfs.size() - 1);
    bsdf_of[&b] = id;
    return id;
  };

  std::vector<AreaLight::Emission> emission;
  for (size_t i = 0; i < desc.meshes.size(); ++i) {
    const auto& mesh = desc.meshes[i];
    const bool overridden = !options.override_meshes.empty() && options.override_meshes[i];
    if (overridden && !options.override_binding)
      throw Error(desc.source, "", "override without a binding");
    const MaterialBinding& b =
        overridden ? *options.override_binding : desc.binding_for(mesh->material);
    Geometry::MeshRecord rec;
    rec.mesh = mesh;
    rec.bsdf = bsdf_index(b);
    const auto info = desc.gltf_materials.find(mesh->material);
    const GltfMaterialInfo gl =
        info != desc.gltf_materials.end() ? info->second : GltfMaterialInfo{};
    emission.push_back({b.emission ? *b.emission : gl.emission,
                        b.double_sided ? *b.double_sided : gl.double_sided});
    geo->meshes.push_back(rec);
    geo->bounds.expand(mesh->bounds());
    // Geometry IDs equal mesh indices; an empty mesh simply has no Embree geometry.
    if (mesh->vertex_count() == 0 || mesh->triangle_count() == 0) continue;

    RTCGeometry g = rtcNewGeometry(geo->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh->vertex_count()));
    auto* ib = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                mesh->triangle_count()));
    if (!vb || !ib) {
      rtcReleaseGeometry(g);
      throw Error(desc.source, "", "Embree could not allocate buffers: " + errors.message);
    }
    if (mesh->vertex_count())
      std::memcpy(vb, mesh->positions.data(), mesh->positions.size() * sizeof(float));
    if (mesh->triangle_count())
      std::memcpy(ib, mesh->indices.data(), mesh->indices.size() * sizeof(uint32_t));
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(geo->scene, g, static_cast<unsigned>(i));
    rtcReleaseGeometry(g);
    geo->triangles += mesh->triangle_count();
  }
  rtcCommitScene(geo->scene);
  if (!errors.message.empty()) throw Error(desc.source, "", errors.message);
  geo->area_light = AreaLight(desc.meshes, emission);
  for (size_t i = 0; i < geo->meshes.size(); ++i)
    geo->meshes[i].emits = geo->area_light.emits(static_cast<uint32_t>(i));
  geo_ = std::move(geo);
  set_lights(desc.lights);
}

const Light* RenderScene::surface_light(uint32_t mesh) const {
  return surface_light_ >= 0 && geo_->meshes[mesh].emits ? &lights_[surface_light_] : nullptr;
}

void RenderScene::set_lights(const Lights& lights) {
  lights_.clear();
  for (const auto& d : lights.directional) lights_.push_back(d);
  for (const auto& p : lights.points) lights_.push_back(p);
  surface_light_ = -1;
  if (!geo_->area_light.empty()) {
    surface_light_ = static_cast<int>(lights_.size());
    lights_.push_back(geo_->area_light);
  }
  if (!lights.environment.is_black()) lights_.push_back(EnvironmentLight{lights.environment});
}

bool RenderScene::intersect(const Ray& ray, SurfaceHit* hit) const {
  RTCRayHit rh = embree_ray(ray);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcIntersect1(geo_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  const auto& rec = geo_->meshes[rh.hit.geomID];
  const TriangleMesh& m = *rec.mesh;
  const uint32_t prim = rh.hit.primID;
  const uint32_t i0 = m.indices[3 * prim], i1 = m.indices[3 * prim + 1],
                 i2 = m.indices[3 * prim + 2];
  const double b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1 - b1 - b2;
  const Vec3 p0 = vertex(m, i0), p1 = vertex(m, i1), p2 = vertex(m, i2);
  hit->t = rh.ray.tfar;
  hit->p = b0 * p0 + b1 * p1 + b2 * p2;
  Vec3 ng = cross(p1 - p0, p2 - p0);
  const double ng_len = length(ng);
  ng = ng_len > 0 ? ng / ng_len : -ray.d;
  hit->ng = ng;
  hit->mesh = rh.hit.geomID;
  hit->prim = prim;
  auto attr3 = [&](const std::vector<float>& a, int stride) {
    return b0 * Vec3{a[stride * i0], a[stride * i0 + 1], a[stride * i0 + 2]} +
           b1 * Vec3{a[stride * i1], a[stride * i1 + 1], a[stride * i1 + 2]} +
           b2 * Vec3{a[stride * i2], a[stride * i2 + 1], a[stride * i2 + 2]};
  };
  Vec3 ns = ng;
  if (!m.normals.empty()) {
    const Vec3 n = attr3(m.normals, 3);
    const double len = length(n);
    if (len > 1e-12) ns = n / len;
  }
  const Vec3 tangent = m.tangents.empty() ? Vec3{} : attr3(m.tangents, 4);
  hit->shading = Frame::from_normal_tangent(ns, tangent);
  if (!m.uvs.empty()) {
    hit->uv = {b0 * m.uvs[2 * i0] + b1 * m.uvs[2 * i1] + b2 * m.uvs[2 * i2],
               b0 * m.uvs[2 * i0 + 1] + b1 * m.uvs[2 * i1 + 1] + b2 * m.uvs[2 * i2 + 1]};
  } else {
    hit->uv = {b1, b2};
  }
  // Float intersection error grows with the coordinates' magnitude: offset relative to it.
  double mag = 0;
  for (const Vec3& p : {p0, p1, p2})
    mag = std::max({mag, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  hit->offset = 2e-6 * mag + 1e-30;  // ~30 float ulps of the largest coordinate
  return true;
}

RTCSceneTy* RenderScene::embree_scene() const {
  return geo_->scene;
}

bool RenderScene::occluded(const Vec3& origin, const Vec3& dir, double tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = static_cast<float>(origin.x);
  r.org_y = static_cast<float>(origin.y);
  r.org_z = static_cast<float>(origin.z);
  r.dir_x = static_cast<float>(dir.x);
  r.dir_y = static_cast<float>(dir.y);
  r.dir_z = static_cast<float>(dir.z);
  r.tnear = 0.0f;
  r.tfar = tmax > 3e38 ? INFINITY : static_cast<float>(tmax);
  r.mask = 0xFFFFFFFFu;
  r.time = 0.0f;
  r.flags = 0;
  rtcOccluded1(geo_->scene, &ctx, &r);
  return r.tfar < 0;  // Embree sets tfar to -inf on a hit
}

const Bsdf& RenderScene::bsdf(uint32_t mesh) const {
  return geo_->bsdfs[geo_->meshes[mesh].bsdf];
}

RenderScene RenderScene::with_lights(const Lights& lights) const {
  RenderScene r;
  r.geo_ = geo_;
  r.set_lights(lights);
  return r;
}

size_t RenderScene::mesh_count() const {
  return geo_->meshes.size();
}
size_t RenderScene::triangle_count() const {
  return geo_->triangles;
}
Bounds3 RenderScene::bounds() const {
  return geo_->bounds;
}

}  // namespace weft
