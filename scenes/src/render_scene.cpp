#include "weft/scenes/render_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <type_traits>
#include <variant>

#include "render_scene_hits.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/registry.h"
#include "weft/scenes/embree_context.h"

namespace weft {

namespace {
struct EmbreeErrors {
  std::mutex mutex;
  std::string message;
};

// A curve set: one Embree geometry (round linear curves, or the tubes' triangles), whose filter
// functions get this record as their user pointer.
struct CurveRecord {
  std::shared_ptr<const FiberCurves> curves;
  FiberSegmentIndex segments;
  std::vector<uint32_t> yarn_bsdf;          // per yarn of 'curves'
  int64_t first_fiber = 0;                  // scene-wide id of curve 0
  std::shared_ptr<const FiberTubes> tubes;  // set when the fibers are tubes
  std::vector<Vec3> tube_unit_normals;      // unit_vertex_normals(tubes->mesh)
  std::vector<uint32_t> prim_curve;         // per Embree primitive (segment or triangle): curve
  double scale = 1;  // of the space Embree traces these primitives in (Geometry::curve_scale)
};
}  // namespace

struct RenderScene::Geometry {
  struct MeshRecord {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<Vec3> unit_normals;  // unit_vertex_normals(*mesh)
    uint32_t bsdf = 0;
    bool emits = false;  // part of the area light
  };
  EmbreeErrors errors;  // outlives the device, which reports into it
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // Round curves live in their own scene, scaled by curve_scale (a power of two, so exactly) and
  // instanced into 'scene' at 1 / curve_scale: Embree's round-curve intersector has absolute
  // tolerances (float epsilon on squared lengths) that fail for fibers of micrometres in metres.
  RTCScene curve_scene = nullptr;
  double curve_scale = 1;
  // Shifted meshes (SceneDescription::mesh_shifts): the meshes in their own scene, instanced into
  // 'scene' once per shift with instance IDs first_mesh_instance + shift index.
  RTCScene mesh_scene = nullptr;
  std::vector<Vec3> mesh_shifts;
  unsigned first_mesh_instance = 0;
  std::vector<MeshRecord> meshes;
  std::vector<CurveRecord> curve_sets;  // reserved once: Embree holds pointers to its elements
  std::vector<Bsdf> bsdfs;
  // The first material without values per band (bsdfs.h spectral_obstacle): its field and why
  // (empty: every material has them).
  std::string spectral_field, spectral_why;
  std::string source;         // the description's, for errors
  bool grey_emission = true;  // every emissive mesh emits the same in R, G and B
  AreaLight area_light;       // the emissive triangles
  Bounds3 bounds;
  size_t triangles = 0, curve_segments = 0;
  int64_t fibers = 0;
  FiberGeometry fiber_geometry;
  bool packets = false;    // the Embree library answers ray packets (rtcIntersect16)
  bool cancelled = false;  // the build was stopped (RenderSceneOptions::build_progress)

  ~Geometry() {
    if (scene) rtcReleaseScene(scene);
    if (curve_scene) rtcReleaseScene(curve_scene);
    if (mesh_scene) rtcReleaseScene(mesh_scene);
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

// The lanes of a packet query for 'rays', each as embree_ray sets it up; the lanes beyond them
// repeat the first ray, switched off in 'valid'.
static_assert(RenderScene::kPacketRays == 16, "packet queries are rtcIntersect16, rtcOccluded16");
void packet_rays(std::span<const Ray> rays, RTCRay16& r, int* valid) {
  for (int i = 0; i < RenderScene::kPacketRays; ++i) {
    const bool used = size_t(i) < rays.size();
    valid[i] = used ? -1 : 0;
    const RTCRay one = embree_ray(used ? rays[i] : rays[0]).ray;
    r.org_x[i] = one.org_x, r.org_y[i] = one.org_y, r.org_z[i] = one.org_z;
    r.dir_x[i] = one.dir_x, r.dir_y[i] = one.dir_y, r.dir_z[i] = one.dir_z;
    r.tnear[i] = one.tnear, r.tfar[i] = one.tfar;
    r.mask[i] = one.mask, r.time[i] = one.time, r.flags[i] = one.flags;
  }
}

FiberSegment segment_of(const CurveRecord& rec, uint32_t segment) {
  const FiberCurves& c = *rec.curves;
  const uint32_t i = rec.segments.first_point[segment];
  return {c.point(i), c.point(i + 1), c.radius(i), c.radius(i + 1)};
}

// Candidate hit i of a filter call: the ray's origin and direction (in the space Embree traces
// the geometry in) and the hit point in world units. Embree has set the ray's tfar to the
// candidate's distance.
struct Candidate {
  Vec3 o, d, p;
  uint32_t prim = 0;
};
Candidate candidate(const CurveRecord& rec, const RTCFilterFunctionNArguments* args, unsigned i) {
  const unsigned n = args->N;
  Candidate c;
  c.prim = RTCHitN_primID(args->hit, n, i);
  c.o = {RTCRayN_org_x(args->ray, n, i), RTCRayN_org_y(args->ray, n, i),
         RTCRayN_org_z(args->ray, n, i)};
  c.d = {RTCRayN_dir_x(args->ray, n, i), RTCRayN_dir_y(args->ray, n, i),
         RTCRayN_dir_z(args->ray, n, i)};
  c.p = (c.o + c.d * static_cast<double>(RTCRayN_tfar(args->ray, n, i))) / rec.scale;
  return c;
}

// Whether the candidate meets its fiber's surface from inside (the ray runs outwards there).
bool meets_from_inside(const CurveRecord& rec, const Candidate& c) {
  Vec3 outward;
  if (rec.tubes) {  // counter-clockwise seen from outside (make_fiber_tubes)
    const TriangleMesh& m = rec.tubes->mesh;
    const Vec3 p0 = m.position(m.indices[3 * c.prim]), p1 = m.position(m.indices[3 * c.prim + 1]),
               p2 = m.position(m.indices[3 * c.prim + 2]);
    outward = cross(p1 - p0, p2 - p0);
  } else {  // the segment's cone or its end sphere: away from the nearest axis point
    const FiberSegment s = segment_of(rec, c.prim);
    outward = c.p - s.axis_point(s.closest_u(c.p));
  }
  return dot(c.d, outward) > 0;
}

// Whether the candidate lies inside one of the ignored fiber's end segments (the next piece of
// a cut fiber begins with an end sphere inside the fiber's own end).
bool inside_ignored_end(const FiberQueryContext& ctx, const Candidate& c) {
  if (!ctx.ends) return false;
  const FiberEnds& ends = *ctx.ends;
  for (int k = 0; k < ends.count; ++k) {
    // Most candidates lie far from both ends: a bounding sphere first.
    if (length_squared(c.p - ends.centre[k]) > ends.reach2[k]) continue;
    const FiberSegment& s = ends.segment[k];
    const double u = s.closest_u(c.p);
    // Within float rounding of the surface counts as inside: there the two end spheres coincide.
    if (length(c.p - s.axis_point(u)) < s.radius_at(u) * (1 + 1e-5)) return true;
  }
  return false;
}

// Embree calls this for every candidate hit on a fiber geometry (intersect and occluded); a
// rejected one lets Embree go on looking behind it. For a ray that leaves a fiber (the query
// ignores it), rejected: hits on that fiber, hits on any fiber from inside, and hits inside the
// fiber's end segments (on its next piece's end sphere). A fiber is shaded
// as a whole, so a ray that leaves it may run through its body; fibers do not overlap, so the
// ray can be inside another only where that one continues the fiber it left: a fiber cut into
// several curves, such as the tiles of a woven sample, whose fibers end at the repeat's sides
// where their continuation begins, the two end spheres overlapping. Such a surface is neither
// shaded (a fiber table sends no light into its fiber) nor a blocker: taken as a hit it stopped
// the light that crosses a joint (docs/fabric-bsdf.md, "One transport, two estimators").
void fiber_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const FiberQueryContext*>(args->context);
  if (ctx->ignore_fiber == kNoFiber) return;
  const auto* rec = static_cast<const CurveRecord*>(args->geometryUserPtr);
  const int64_t local = ctx->ignore_fiber - rec->first_fiber;
  const bool ignored_here = local >= 0 && local < static_cast<int64_t>(rec->curves->curve_count());
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    if (ignored_here &&
        rec->prim_curve[RTCHitN_primID(args->hit, args->N, i)] == static_cast<uint32_t>(local)) {
      args->valid[i] = 0;
      continue;
    }
    const Candidate c = candidate(*rec, args, i);
    if (inside_ignored_end(*ctx, c) || meets_from_inside(*rec, c)) args->valid[i] = 0;
  }
}

}  // namespace

// Builds a RenderScene's Geometry from a description, one step per method (a member of
// RenderScene, so it may name the private Geometry).
class RenderScene::Builder {
 public:
  // The Embree device and scene; checks the override mask.
  Builder(const SceneDescription& desc, const RenderSceneOptions& options);
  void add_meshes();       // geometry ID = mesh index (in the mesh scene when shifted)
  void instance_meshes();  // one instance of the mesh scene per shift
  void add_curve_sets();   // after the meshes: their fibers' shape IDs follow the meshes'
  void instance_curve_scene();
  std::shared_ptr<const Geometry> finish();

 private:
  // One BSDF per binding, created once and shared by every shape that uses it.
  uint32_t bsdf_index(const MaterialBinding& b);
  // The binding of material 'key' on 'shape': the options' override where its mask says so.
  const MaterialBinding& binding(size_t shape, const std::string& key) const;
  // An Embree triangle geometry holding a copy of the mesh's vertices and triangles.
  RTCGeometry triangle_geometry(const TriangleMesh& m);        // nullptr when stopped
  bool copy_polled(void* to, const void* from, size_t bytes);  // false when stopped
  void start_curve_sets();  // the fiber geometry, checks and the curve scene
  void add_curve_set(size_t k);
  RTCGeometry tube_geometry(CurveRecord& rec);
  RTCGeometry round_curve_geometry(CurveRecord& rec, size_t k);
  bool index_segments_polled(const FiberCurves& curves, FiberSegmentIndex& out);
  [[noreturn]] void allocation_failed(RTCGeometry g) const;

  const SceneDescription& desc_;
  const RenderSceneOptions& options_;
  std::shared_ptr<Geometry> geo_ = std::make_shared<Geometry>();
  std::map<const MaterialBinding*, uint32_t> bsdf_of_;
  std::shared_ptr<TableCache> cache_;
  std::vector<AreaLight::Emission> emission_;  // per mesh
  bool tubes_ = false;                         // the fibers are triangle tubes

  // Embree calls the monitor from its build threads, at once: one of them at a time asks the
  // options' callback (not made for threads), the others go on; once it says stop, all stop.
  struct Monitor {
    const ProgressCallback* progress = nullptr;
    std::mutex mutex;
    std::atomic<bool> stop{false};
  } monitor_;
  static bool on_build_progress(void* user, double fraction);
  void monitor(RTCScene scene) {
    rtcSetSceneProgressMonitorFunction(scene, on_build_progress, &monitor_);
  }
  // Whether to go on (between geometries, asking the callback as a monitor would).
  bool keep_going() { return on_build_progress(&monitor_, -1); }
};

bool RenderScene::Builder::on_build_progress(void* user, double fraction) {
  auto* m = static_cast<Monitor*>(user);
  if (m->stop.load()) return false;
  std::unique_lock lock(m->mutex, std::try_to_lock);
  if (!lock.owns_lock()) return true;
  const uint64_t done =
      fraction < 0 ? 0 : static_cast<uint64_t>(std::clamp(fraction, 0.0, 1.0) * 1000);
  if (!(*m->progress)(
          {"scene build", done, fraction < 0 ? uint64_t{0} : uint64_t{1000}, "permille"}))
    m->stop = true;
  return !m->stop.load();
}

RenderScene::Builder::Builder(const SceneDescription& desc, const RenderSceneOptions& options)
    : desc_(desc), options_(options) {
  monitor_.progress = &options_.build_progress;
  geo_->device = rtcNewDevice(nullptr);
  if (!geo_->device) throw Error(desc.source, "", "cannot create the Embree device");
  rtcSetDeviceErrorFunction(geo_->device, on_embree_error, &geo_->errors);
  geo_->packets = rtcGetDeviceProperty(geo_->device, RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED) != 0;
  geo_->scene = rtcNewScene(geo_->device);
  rtcSetSceneFlags(geo_->scene, RTC_SCENE_FLAG_ROBUST);  // watertight: no leaks along shared edges
  rtcSetSceneBuildQuality(geo_->scene, RTC_BUILD_QUALITY_HIGH);
  monitor(geo_->scene);

  if (!options.override_shapes.empty() && options.override_shapes.size() != desc.shape_count())
    throw Error(desc.source, "", "override mask does not match the shape count");
  cache_ = options.table_cache ? options.table_cache : std::make_shared<TableCache>();
}

uint32_t RenderScene::Builder::bsdf_index(const MaterialBinding& b) {
  const auto it = bsdf_of_.find(&b);
  if (it != bsdf_of_.end()) return it->second;
  MaterialContext ctx;
  ctx.base_dir = desc_.base_dir;
  ctx.source_file = desc_.source;
  ctx.field_prefix = b.field.empty() ? "materials" : b.field + ".params";
  ctx.cache = cache_;
  ctx.progress = options_.material_progress;
  ctx.fiber_tables = options_.fiber_tables;
  geo_->bsdfs.push_back(make_bsdf(b.type, b.params, ctx));
  const auto id = static_cast<uint32_t>(geo_->bsdfs.size() - 1);
  if (geo_->spectral_why.empty()) {
    geo_->spectral_why = spectral_obstacle(geo_->bsdfs.back());
    if (!geo_->spectral_why.empty()) geo_->spectral_field = b.field.empty() ? "materials" : b.field;
  }
  bsdf_of_[&b] = id;
  return id;
}

const MaterialBinding& RenderScene::Builder::binding(size_t shape, const std::string& key) const {
  const bool o = !options_.override_shapes.empty() && options_.override_shapes[shape];
  if (o && !options_.override_binding) throw Error(desc_.source, "", "override without a binding");
  return o ? *options_.override_binding : desc_.binding_for(key);
}

void RenderScene::Builder::allocation_failed(RTCGeometry g) const {
  rtcReleaseGeometry(g);
  throw Error(desc_.source, "", "Embree could not allocate buffers: " + geo_->errors.message);
}

bool RenderScene::Builder::copy_polled(void* to, const void* from, size_t bytes) {
  // 64 MB: tens of milliseconds on a loaded machine, the new pages' faults included.
  constexpr size_t kSlice = size_t{64} << 20;
  for (size_t at = 0; at < bytes; at += kSlice) {
    if (!keep_going()) return false;
    std::memcpy(static_cast<char*>(to) + at, static_cast<const char*>(from) + at,
                std::min(kSlice, bytes - at));
  }
  return true;
}

RTCGeometry RenderScene::Builder::triangle_geometry(const TriangleMesh& m) {
  RTCGeometry g = rtcNewGeometry(geo_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.vertex_count()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), m.triangle_count()));
  if (!vb || !ib) allocation_failed(g);
  // A yarn sample's mesh is over a gigabyte: copied with polls, so that a stop need not wait.
  if (!copy_polled(vb, m.positions.data(), m.positions.size() * sizeof(float)) ||
      !copy_polled(ib, m.indices.data(), m.indices.size() * sizeof(uint32_t))) {
    rtcReleaseGeometry(g);
    return nullptr;
  }
  return g;
}

void RenderScene::Builder::add_meshes() {
  if (!desc_.mesh_shifts.empty()) {
    geo_->mesh_scene = rtcNewScene(geo_->device);
    rtcSetSceneFlags(geo_->mesh_scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(geo_->mesh_scene, RTC_BUILD_QUALITY_HIGH);
    monitor(geo_->mesh_scene);
  }
  // A yarn sample's two meshes hold up to 5e7 triangles: between meshes and within each step on
  // a mesh's vertices, the build asks whether to go on, and once stopped it adds nothing more.
  for (size_t i = 0; i < desc_.meshes.size() && keep_going(); ++i) {
    const auto& mesh = desc_.meshes[i];
    const MaterialBinding& b = binding(i, mesh->material);
    Geometry::MeshRecord rec;
    rec.mesh = mesh;
    rec.unit_normals = unit_vertex_normals(*mesh, [this] { return keep_going(); });
    if (monitor_.stop) return;
    rec.bsdf = bsdf_index(b);
    const auto info = desc_.gltf_materials.find(mesh->material);
    const GltfMaterialInfo gl =
        info != desc_.gltf_materials.end() ? info->second : GltfMaterialInfo{};
    emission_.push_back({b.emission ? *b.emission : gl.emission,
                         b.double_sided ? *b.double_sided : gl.double_sided});
    geo_->meshes.push_back(std::move(rec));
    const Bounds3 mb = mesh->bounds();  // once: a pass over every vertex
    if (desc_.mesh_shifts.empty()) geo_->bounds.expand(mb);
    for (const Vec3& s : desc_.mesh_shifts) geo_->bounds.expand(Bounds3{mb.lo + s, mb.hi + s});
    // Geometry IDs equal mesh indices; an empty mesh simply has no Embree geometry.
    if (mesh->vertex_count() == 0 || mesh->triangle_count() == 0) continue;

    RTCGeometry g = triangle_geometry(*mesh);
    if (!g) return;
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(geo_->mesh_scene ? geo_->mesh_scene : geo_->scene, g,
                          static_cast<unsigned>(i));
    rtcReleaseGeometry(g);
    geo_->triangles += mesh->triangle_count();
  }
}

void RenderScene::Builder::instance_meshes() {
  if (!geo_->mesh_scene || monitor_.stop) return;
  for (size_t i = 0; i < emission_.size(); ++i)
    if (!emission_[i].radiance.is_black())
      throw Error(desc_.source, "mesh_shifts",
                  "mesh " + std::to_string(i) +
                      " emits light: shifted copies of emissive meshes are not supported");
  rtcCommitScene(geo_->mesh_scene);
  geo_->mesh_shifts = desc_.mesh_shifts;
  geo_->first_mesh_instance = static_cast<unsigned>(desc_.shape_count() + 1);
  for (size_t q = 0; q < geo_->mesh_shifts.size(); ++q) {
    const Vec3& s = geo_->mesh_shifts[q];
    RTCGeometry inst = rtcNewGeometry(geo_->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, geo_->mesh_scene);
    const auto dx = static_cast<float>(s.x), dy = static_cast<float>(s.y),
               dz = static_cast<float>(s.z);
    const float xfm[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, dx, dy, dz};  // 3 x 4, column-major
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(inst);
    rtcAttachGeometryByID(geo_->scene, inst, geo_->first_mesh_instance + static_cast<unsigned>(q));
    rtcReleaseGeometry(inst);
  }
}

void RenderScene::Builder::start_curve_sets() {
  geo_->fiber_geometry = options_.fiber_geometry.value_or(desc_.fiber_geometry);
  tubes_ = geo_->fiber_geometry.type == FiberGeometry::Type::tubes;
  if (!desc_.curves.empty() &&
      rtcGetDeviceProperty(geo_->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) == 0)
    throw Error(desc_.source, "curves",
                "this Embree is built without filter functions, which fibers need");
  for (size_t k = 0; k < desc_.curves.size(); ++k)
    desc_.curves[k]->validate(desc_.source, "curves[" + std::to_string(k) + "]");
  geo_->curve_sets.reserve(desc_.curves.size());
  if (tubes_ || desc_.curves.empty()) return;
  // The scale that makes the mean fiber radius about 1.
  double sum = 0;
  size_t n = 0;
  for (const auto& c : desc_.curves)
    for (size_t i = 0; i < c->point_count(); ++i) sum += c->radius(i), ++n;
  if (n > 0) geo_->curve_scale = std::ldexp(1.0, std::clamp(-std::ilogb(sum / n), -100, 100));
  geo_->curve_scene = rtcNewScene(geo_->device);
  rtcSetSceneFlags(geo_->curve_scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(geo_->curve_scene, RTC_BUILD_QUALITY_HIGH);
  monitor(geo_->curve_scene);
}

// Fibers: one Embree geometry per curve set, with the filter that ignores the query's fiber.
void RenderScene::Builder::add_curve_sets() {
  start_curve_sets();
  for (size_t k = 0; k < desc_.curves.size() && keep_going(); ++k) add_curve_set(k);
}

void RenderScene::Builder::add_curve_set(size_t k) {
  const size_t shape = desc_.meshes.size() + k;
  const auto& curves = desc_.curves[k];
  CurveRecord& rec = geo_->curve_sets.emplace_back();
  rec.curves = curves;
  rec.scale = tubes_ ? 1.0 : geo_->curve_scale;
  if (!index_segments_polled(*curves, rec.segments)) return;
  rec.first_fiber = geo_->fibers;
  geo_->fibers += static_cast<int64_t>(curves->curve_count());
  for (const std::string& key : curves->yarn_material) {
    const MaterialBinding& b = binding(shape, key);
    if (b.emission && !b.emission->is_black())
      throw Error(desc_.source, b.field.empty() ? "materials" : b.field + ".emission",
                  "fibers do not emit light: bind emission to meshes only");
    rec.yarn_bsdf.push_back(bsdf_index(b));
  }
  geo_->bounds.expand(curves->bounds());
  if (curves->curve_count() == 0) return;

  RTCGeometry g = tubes_ ? tube_geometry(rec) : round_curve_geometry(rec, k);
  if (!g) return;  // stopped (triangle_geometry)
  rtcSetGeometryUserData(g, &rec);
  rtcSetGeometryIntersectFilterFunction(g, fiber_filter);
  rtcSetGeometryOccludedFilterFunction(g, fiber_filter);
  rtcCommitGeometry(g);
  // Tubes take the shape's ID in the scene; round curves ID k in the instanced curve scene.
  if (tubes_)
    rtcAttachGeometryByID(geo_->scene, g, static_cast<unsigned>(shape));
  else
    rtcAttachGeometryByID(geo_->curve_scene, g, static_cast<unsigned>(k));
  rtcReleaseGeometry(g);
}

RTCGeometry RenderScene::Builder::tube_geometry(CurveRecord& rec) {
  auto t =
      std::make_shared<FiberTubes>(make_fiber_tubes(*rec.curves, geo_->fiber_geometry.tube_sides));
  rec.prim_curve.resize(t->triangle_segment.size());
  for (size_t i = 0; i < t->triangle_segment.size(); ++i)
    rec.prim_curve[i] = rec.segments.curve[t->triangle_segment[i]];
  RTCGeometry g = triangle_geometry(t->mesh);
  if (!g) return nullptr;
  geo_->triangles += t->mesh.triangle_count();
  rec.tube_unit_normals = unit_vertex_normals(t->mesh);
  rec.tubes = std::move(t);
  return g;
}

// index_segments, asked to go on every million segments: near the limit of 3e7 curve points the
// index is 240 MB of new pages, seconds on a loaded machine. False when stopped ('out' partial).
bool RenderScene::Builder::index_segments_polled(const FiberCurves& curves,
                                                 FiberSegmentIndex& out) {
  constexpr size_t kSegmentsPerPoll = size_t(1) << 20;
  out.first_point.reserve(curves.segment_count());
  out.curve.reserve(curves.segment_count());
  size_t next_poll = kSegmentsPerPoll;
  for (size_t c = 0; c < curves.curve_count(); ++c) {
    for (uint32_t k = 0; k + 1 < curves.curve_points[c]; ++k) {
      out.first_point.push_back(curves.curve_first[c] + k);
      out.curve.push_back(static_cast<uint32_t>(c));
    }
    if (out.curve.size() >= next_poll) {
      if (!keep_going()) return false;
      next_poll = out.curve.size() + kSegmentsPerPoll;
    }
  }
  return true;
}

RTCGeometry RenderScene::Builder::round_curve_geometry(CurveRecord& rec, size_t k) {
  const FiberCurves& curves = *rec.curves;
  rec.prim_curve = rec.segments.curve;
  const size_t nseg = rec.segments.first_point.size();
  RTCGeometry g = rtcNewGeometry(geo_->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), curves.point_count()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), nseg));
  // Neighbour flags: a fiber's inner joints attach, only its two ends are closed by spheres.
  auto* fb = static_cast<uint8_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, 1, nseg));
  if (!(vb && ib && fb)) allocation_failed(g);
  const auto scale = static_cast<float>(geo_->curve_scale);
  bool in_range = true;
  // Polled every 8 MB of the buffers: near the limit of 3e7 points they are 650 MB of new pages
  // per curve set, seconds each on a loaded machine.
  constexpr size_t kPerPoll = size_t(1) << 21;
  const auto stopped = [&](size_t i) {
    if ((i + 1) % kPerPoll != 0 || keep_going()) return false;
    rtcReleaseGeometry(g);
    return true;
  };
  for (size_t i = 0; i < curves.points.size(); ++i) {
    vb[i] = curves.points[i] * scale;  // exact: a power of two
    in_range = in_range && std::abs(vb[i]) < 1e37f;
    if (stopped(i)) return nullptr;
  }
  if (!in_range) {
    rtcReleaseGeometry(g);
    throw Error(desc_.source, "curves[" + std::to_string(k) + "]",
                "fiber coordinates too large for their radii");
  }
  if (!copy_polled(ib, rec.segments.first_point.data(), nseg * sizeof(uint32_t))) {
    rtcReleaseGeometry(g);
    return nullptr;
  }
  for (size_t s = 0; s < nseg; ++s) {
    const uint32_t c = rec.segments.curve[s], first = curves.curve_first[c];
    const uint32_t last = first + curves.curve_points[c] - 2;  // its last segment's start
    const uint32_t at = rec.segments.first_point[s];
    fb[s] = static_cast<uint8_t>((at > first ? RTC_CURVE_FLAG_NEIGHBOR_LEFT : 0) |
                                 (at < last ? RTC_CURVE_FLAG_NEIGHBOR_RIGHT : 0));
    if (stopped(s)) return nullptr;
  }
  geo_->curve_segments += nseg;
  return g;
}

void RenderScene::Builder::instance_curve_scene() {
  if (!geo_->curve_scene || monitor_.stop) return;
  rtcCommitScene(geo_->curve_scene);
  if (monitor_.stop) return;
  RTCGeometry inst = rtcNewGeometry(geo_->device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(inst, geo_->curve_scene);
  const auto inv = static_cast<float>(1 / geo_->curve_scale);
  const float xfm[12] = {inv, 0, 0, 0, inv, 0, 0, 0, inv, 0, 0, 0};  // 3 x 4, column-major
  rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  rtcCommitGeometry(inst);
  rtcAttachGeometryByID(geo_->scene, inst, static_cast<unsigned>(desc_.shape_count()));
  rtcReleaseGeometry(inst);
}

std::shared_ptr<const RenderScene::Geometry> RenderScene::Builder::finish() {
  if (!monitor_.stop) rtcCommitScene(geo_->scene);
  // A cancelled build's Embree error (RTC_ERROR_CANCELLED) is no error of the scene's.
  if (monitor_.stop) {
    geo_->cancelled = true;
    return std::move(geo_);
  }
  if (!geo_->errors.message.empty()) throw Error(desc_.source, "", geo_->errors.message);
  geo_->area_light = AreaLight(desc_.meshes, emission_);
  geo_->source = desc_.source;
  for (const AreaLight::Emission& e : emission_)
    geo_->grey_emission = geo_->grey_emission && e.radiance.is_grey();
  for (size_t i = 0; i < geo_->meshes.size(); ++i)
    geo_->meshes[i].emits = geo_->area_light.emits(static_cast<uint32_t>(i));
  return std::move(geo_);
}

RenderScene::RenderScene(const SceneDescription& desc, const RenderSceneOptions& options) {
  Builder b(desc, options);
  b.add_meshes();
  b.instance_meshes();
  b.add_curve_sets();
  b.instance_curve_scene();
  geo_ = b.finish();
  if (geo_->cancelled) return;
  packets_ = geo_->packets;
  set_lights(desc.lights);
  find_woven_meshes(desc);
}

const Light* RenderScene::surface_light(uint32_t shape) const {
  return surface_light_ >= 0 && shape < geo_->meshes.size() && geo_->meshes[shape].emits
             ? &lights_[surface_light_]
             : nullptr;
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
  for (const auto& map : lights.environment_maps) lights_.push_back(map);
}

std::optional<FiberEnds> RenderScene::fiber_ends(int64_t ignore_fiber) const {
  if (ignore_fiber == kNoFiber || ignore_fiber < 0 || ignore_fiber >= geo_->fibers)
    return std::nullopt;
  const FiberRef r = fiber_ref(ignore_fiber);
  const FiberCurves& c = *geo_->curve_sets[r.curve_set].curves;
  const uint32_t first = c.curve_first[r.curve], last = first + c.curve_points[r.curve] - 2;
  // Tubes reach out to their polygon's corners.
  const double corner = geo_->fiber_geometry.type == FiberGeometry::Type::tubes
                            ? tube_corner_radius_scale(geo_->fiber_geometry.tube_sides)
                            : 1.0;
  FiberEnds ends;
  for (const uint32_t i : {first, last}) {
    const FiberSegment s{c.point(i), c.point(i + 1), c.radius(i) * corner,
                         c.radius(i + 1) * corner};
    const double reach = 0.5 * length(s.p1 - s.p0) + 1.01 * std::max(s.r0, s.r1);
    ends.centre[ends.count] = 0.5 * (s.p0 + s.p1);
    ends.reach2[ends.count] = reach * reach;
    ends.segment[ends.count++] = s;
  }
  return ends;
}

bool RenderScene::intersect(const Ray& ray, SurfaceHit* hit, int64_t ignore_fiber) const {
  RTCRayHit rh = embree_ray(ray);
  const std::optional<FiberEnds> ends =
      ignore_fiber == kNoFiber ? std::nullopt : fiber_ends(ignore_fiber);  // most queries: none
  FiberQueryContext ctx(ignore_fiber, ends ? &*ends : nullptr);
  rtcIntersect1(geo_->scene, &ctx.embree, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  record_hit(ray, {rh.hit.geomID, rh.hit.instID[0], rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar},
             hit);
  return true;
}

void RenderScene::intersect_coherent(std::span<const Ray> rays, SurfaceHit* const* hits,
                                     bool* found) const {
  if (rays.size() > size_t(kPacketRays))
    throw Error("", "intersect_coherent", "more rays than a packet holds");
  // Embree built without packets answers rtcIntersect16 with an error and no hits.
  if (rays.size() < 2 || !packets_) {
    for (size_t i = 0; i < rays.size(); ++i) found[i] = intersect(rays[i], hits[i]);
    return;
  }
  RTCRayHit16 rh;  // 64-byte aligned by its type, as rtcIntersect16 requires
  alignas(64) int valid[kPacketRays];
  packet_rays(rays, rh.ray, valid);
  for (int i = 0; i < kPacketRays; ++i) {
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  FiberQueryContext ctx(kNoFiber, nullptr);
  ctx.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect16(valid, geo_->scene, &ctx.embree, &rh);
  for (size_t i = 0; i < rays.size(); ++i) {
    found[i] = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    if (found[i])
      record_hit(rays[i],
                 {rh.hit.geomID[i], rh.hit.instID[0][i], rh.hit.primID[i], rh.hit.u[i], rh.hit.v[i],
                  rh.ray.tfar[i]},
                 hits[i]);
  }
}

void RenderScene::record_hit(const Ray& ray, const EmbreeHit& h, SurfaceHit* hit) const {
  hit->t = h.t;
  hit->shape = h.geom;
  if (h.inst == RTC_INVALID_GEOMETRY_ID && h.geom < geo_->meshes.size()) {
    const Geometry::MeshRecord& m = geo_->meshes[h.geom];
    triangle_hit(*m.mesh, m.unit_normals, h.prim, h.u, h.v, ray, hit);
    hit->fiber = kNoFiber;
    hit->segment = 0;
    return;
  }
  if (geo_->mesh_scene && h.inst != RTC_INVALID_GEOMETRY_ID &&
      h.inst >= geo_->first_mesh_instance) {
    const Vec3& shift = geo_->mesh_shifts[h.inst - geo_->first_mesh_instance];
    const Geometry::MeshRecord& m = geo_->meshes[h.geom];
    triangle_hit(*m.mesh, m.unit_normals, h.prim, h.u, h.v, ray, hit, &shift);
    hit->fiber = kNoFiber;
    hit->segment = 0;
    return;
  }
  // Round curves are hit inside the curve scene's instance, where geomID is the curve set.
  const bool instanced = h.inst != RTC_INVALID_GEOMETRY_ID;
  const size_t set = instanced ? h.geom : h.geom - geo_->meshes.size();
  hit->shape = static_cast<uint32_t>(geo_->meshes.size() + set);
  const CurveRecord& rec = geo_->curve_sets[set];
  if (rec.tubes) {
    triangle_hit(rec.tubes->mesh, rec.tube_unit_normals, h.prim, h.u, h.v, ray, hit);
    hit->segment = rec.tubes->triangle_segment[h.prim];
  } else {
    hit->segment = h.prim;
    curve_hit(segment_of(rec, hit->segment), hit->t, ray, hit);
    hit->prim = hit->segment;
  }
  hit->fiber = rec.first_fiber + rec.segments.curve[hit->segment];
}

RTCSceneTy* RenderScene::embree_scene() const {
  return geo_->scene;
}

bool RenderScene::occluded(const Vec3& origin, const Vec3& dir, double tmax,
                           int64_t ignore_fiber) const {
  const std::optional<FiberEnds> ends =
      ignore_fiber == kNoFiber ? std::nullopt : fiber_ends(ignore_fiber);  // most queries: none
  FiberQueryContext ctx(ignore_fiber, ends ? &*ends : nullptr);
  RTCRay r = embree_ray({origin, dir, tmax}).ray;
  rtcOccluded1(geo_->scene, &ctx.embree, &r);
  return r.tfar < 0;  // Embree sets tfar to -inf on a hit
}

void RenderScene::occluded_coherent(std::span<const Ray> rays, bool* blocked) const {
  if (rays.size() > size_t(kPacketRays))
    throw Error("", "occluded_coherent", "more rays than a packet holds");
  if (rays.size() < 2 || !packets_) {
    for (size_t i = 0; i < rays.size(); ++i)
      blocked[i] = occluded(rays[i].o, rays[i].d, rays[i].tmax);
    return;
  }
  RTCRay16 r;  // 64-byte aligned by its type, as rtcOccluded16 requires
  alignas(64) int valid[kPacketRays];
  packet_rays(rays, r, valid);
  FiberQueryContext ctx(kNoFiber, nullptr);
  ctx.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcOccluded16(valid, geo_->scene, &ctx.embree, &r);
  for (size_t i = 0; i < rays.size(); ++i) blocked[i] = r.tfar[i] < 0;
}

const Bsdf& RenderScene::bsdf(const SurfaceHit& hit) const {
  if (!hit.on_fiber()) return geo_->bsdfs[geo_->meshes[hit.shape].bsdf];
  const CurveRecord& rec = geo_->curve_sets[hit.shape - geo_->meshes.size()];
  const auto curve = static_cast<size_t>(hit.fiber - rec.first_fiber);
  return geo_->bsdfs[rec.yarn_bsdf[rec.curves->curve_yarn[curve]]];
}

void RenderScene::check_spectral() const {
  if (!geo_->spectral_why.empty())
    throw Error(geo_->source, geo_->spectral_field,
                "a spectral render needs spectral values of every material: " + geo_->spectral_why);
  auto refuse = [&](const std::string& what) {
    throw Error(geo_->source, "lights",
                "a spectral render needs lights of one colour at every wavelength (grey: equal R, "
                "G and B): " +
                    what);
  };
  if (!geo_->grey_emission) refuse("an emissive material's emission is coloured");
  for (const Light& light : lights_)
    std::visit(
        [&](const auto& l) {
          using T = std::decay_t<decltype(l)>;
          if constexpr (std::is_same_v<T, DirectionalLight>) {
            if (!l.irradiance.is_grey()) refuse("a parallel light's irradiance is coloured");
          } else if constexpr (std::is_same_v<T, PointLight>) {
            if (!l.intensity.is_grey()) refuse("a point light's intensity is coloured");
          } else if constexpr (std::is_same_v<T, EnvironmentLight>) {
            if (!l.radiance.is_grey()) refuse("the environment's radiance is coloured");
          } else if constexpr (std::is_same_v<T, EnvironmentMap>) {
            if (!l.is_grey()) refuse("an environment map's texels are coloured");
          }
        },
        light.variant());
}

size_t RenderScene::fiber_count() const {
  return static_cast<size_t>(geo_->fibers);
}

RenderScene::FiberRef RenderScene::fiber_ref(int64_t fiber) const {
  if (fiber < 0 || fiber >= geo_->fibers)
    throw Error("", "fiber",
                "fiber id " + std::to_string(fiber) + " out of range (" +
                    std::to_string(geo_->fibers) + " fibers)");
  // The last curve set whose first fiber is <= fiber (sets with no curves are skipped over).
  const auto& sets = geo_->curve_sets;
  const auto it =
      std::upper_bound(sets.begin(), sets.end(), fiber,
                       [](int64_t f, const CurveRecord& r) { return f < r.first_fiber; });
  auto k = static_cast<size_t>(it - sets.begin()) - 1;
  while (sets[k].curves->curve_count() == 0) --k;  // an empty set shares its successor's start
  FiberRef r;
  r.curve_set = static_cast<uint32_t>(k);
  r.shape = static_cast<uint32_t>(geo_->meshes.size() + k);
  r.curve = static_cast<uint32_t>(fiber - sets[k].first_fiber);
  return r;
}

FiberSegment RenderScene::fiber_segment(const SurfaceHit& hit) const {
  if (!hit.on_fiber() || hit.shape < geo_->meshes.size())
    throw Error("", "hit", "not a hit on a fiber");
  return segment_of(geo_->curve_sets[hit.shape - geo_->meshes.size()], hit.segment);
}

std::vector<FiberSegment> RenderScene::fiber_segments(int64_t fiber) const {
  const FiberRef r = fiber_ref(fiber);
  const FiberCurves& c = *geo_->curve_sets[r.curve_set].curves;
  std::vector<FiberSegment> out;
  const uint32_t first = c.curve_first[r.curve];
  for (uint32_t k = 0; k + 1 < c.curve_points[r.curve]; ++k)
    out.push_back(
        {c.point(first + k), c.point(first + k + 1), c.radius(first + k), c.radius(first + k + 1)});
  return out;
}

FiberGeometry RenderScene::fiber_geometry() const {
  return geo_->fiber_geometry;
}

RenderScene RenderScene::with_lights(const Lights& lights) const {
  RenderScene r;
  r.geo_ = geo_;
  r.packets_ = packets_;
  r.woven_ = woven_;
  r.weave_on_ = weave_on_;
  r.set_lights(lights);
  return r;
}

RenderScene RenderScene::with_ray_packets(bool on) const {
  RenderScene r = *this;
  r.packets_ = on && geo_->packets;
  return r;
}

size_t RenderScene::mesh_count() const {
  return geo_->meshes.size();
}
size_t RenderScene::shape_count() const {
  return geo_->meshes.size() + geo_->curve_sets.size();
}
size_t RenderScene::triangle_count() const {
  return geo_->triangles;
}
bool RenderScene::cancelled() const {
  return geo_->cancelled;
}
size_t RenderScene::curve_segment_count() const {
  return geo_->curve_segments;
}
Bounds3 RenderScene::bounds() const {
  return geo_->bounds;
}

}  // namespace weft
