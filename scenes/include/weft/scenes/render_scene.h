#pragma once
// The immutable, renderable form of a SceneDescription: an Embree 3 scene committed once, one BSDF
// per material binding (created once through the material registry), and its lights (lights.h):
// the description's, plus the emissive triangles as one area light. Fibers (the description's
// curve sets) become Embree round linear curves or triangle tubes (FiberGeometry). Copies share
// the geometry; with_lights() swaps the description's lights without rebuilding anything.
// Thread-safe for concurrent queries.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "weft/core/frame.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bound_bsdf.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/description.h"
#include "weft/scenes/lights.h"
#include "weft/scenes/mesh.h"

struct RTCSceneTy;  // Embree's scene (RTCScene is a pointer to it)

namespace weft {

struct FiberEnds;  // embree_context.h

// Fiber ids are scene-wide: the curves of the description's curve sets numbered in order (set 0's
// curves first). kNoFiber: a triangle of a mesh, or "ignore nothing" in queries.
inline constexpr int64_t kNoFiber = -1;

struct SurfaceHit {
  double t = 0;
  Vec3 p;  // position (double precision): barycentric on triangles, on the fiber's surface
  // Unit geometric normal: triangles' front side = counter-clockwise winding; on a round fiber the
  // radial direction from the segment's axis (outward).
  Vec3 ng;
  // Shading frame, not flipped: the mesh's normal (z) and tangent (x); on a fiber (round or tube)
  // the fiber frame: x = unit tangent along the segment, z = outward normal, y = z x x.
  Frame shading;
  Vec2 uv;  // triangles: texture coordinates (or barycentrics); fibers: (u along segment, 0)
  uint32_t shape = 0;        // the description's shape: mesh index, or meshes.size() + curve set
  uint32_t prim = 0;         // triangle index (tubes too), or the segment index of a round curve
  int64_t fiber = kNoFiber;  // scene-wide fiber id; kNoFiber for mesh triangles
  uint32_t segment = 0;      // fibers: segment index within the curve set (index_segments order)
  double offset = 0;  // distance to move ray origins off the surface (scales with coordinates)
  // Triangles with vertex normals: from p to the smooth surface those normals describe, on the
  // front (normals') side and on the back side (Hanika 2021, "Hacking the shadow terminator",
  // Ray Tracing Gems II ch. 4: p projected onto each corner's tangent plane where it lies below
  // it, the projections blended by the barycentrics). Zero on flat or concave parts, on meshes
  // without normals and on fibers. The path tracer starts shadow rays there (path_tracer.cpp).
  Vec3 lift_front, lift_back;

  bool on_fiber() const { return fiber != kNoFiber; }
  // Origin for a ray leaving the surface in direction d: offset along ng to d's side, so rays
  // continue through the surface for transmission and do not re-hit it.
  Vec3 spawn_origin(const Vec3& d) const { return p + ng * (dot(d, ng) > 0 ? offset : -offset); }
};

struct RenderSceneOptions {
  // Material keys replaced by another binding (e.g. the white reference of the gonioreflectometer).
  std::vector<uint8_t>
      override_shapes;  // per shape (SceneDescription::select_object); empty = none
  std::optional<MaterialBinding> override_binding;
  // How fibers are represented; unset: the description's fiber_geometry.
  std::optional<FiberGeometry> fiber_geometry;
  // Tables (fiber/fabric BSDFs, measured networks) are loaded once into this cache and shared
  // between bindings and between scenes that pass the same cache; null: one cache per scene.
  std::shared_ptr<TableCache> table_cache;
  // Fiber tables a material names by spec: who makes them (null: "spec" is an error) and the
  // progress of that work.
  FiberTableResolver fiber_tables;
  ProgressCallback material_progress = no_progress();
  // Told how far the build of the acceleration structure is, and asked whether to go on: a fiber
  // sample of millions of segments takes tens of seconds. When it says stop, the scene is made
  // cancelled() and must not be traced.
  ProgressCallback build_progress = no_progress();
};

class RenderScene {
 public:
  explicit RenderScene(const SceneDescription& desc, const RenderSceneOptions& options = {});

  // The closest hit along the ray, ignoring every primitive of fiber 'ignore_fiber' (kNoFiber:
  // ignore nothing). A fiber is shaded as a whole (docs/fiber-bsdf.md): rays leaving a point of a
  // fiber pass through that fiber and meet every other one from outside. Where a fiber is cut
  // into several curves (a woven sample's tiles join each fiber to its continuation across the
  // repeat's sides) the ray runs on through the next piece too: for a ray that leaves a fiber,
  // no fiber is met from inside, nor inside the left fiber's end segments. Embree filter
  // functions on the fiber geometries do the ignoring; meshes have none, so triangle-only scenes
  // pay nothing for it. A hit sets every field of *hit, so one record may serve many queries.
  bool intersect(const Ray& ray, SurfaceHit* hit, int64_t ignore_fiber = kNoFiber) const;
  // The closest hits of up to kPacketRays rays that start close together and run nearly parallel
  // (the camera rays of one pixel), ignoring no fiber: found[i] says whether rays[i] hit, and
  // then *hits[i] is set. One Embree packet query with the coherent flag, which answers such rays
  // on triangle meshes two to three times as fast as one by one (docs/PERFORMANCE.md); each hit
  // is, bit for bit, the one intersect() finds.
  static constexpr int kPacketRays = 16;
  void intersect_coherent(std::span<const Ray> rays, SurfaceHit* const* hits, bool* found) const;
  // Whether anything but fiber 'ignore_fiber' lies along origin + t dir, 0 < t < tmax.
  bool occluded(const Vec3& origin, const Vec3& dir, double tmax,
                int64_t ignore_fiber = kNoFiber) const;
  // Whether each of up to kPacketRays rays (from o along the unit d, 0 < t < tmax; ignoring no
  // fiber) is blocked, as occluded() answers it, bit for bit: one packet query with the coherent
  // flag (the shadow rays of a pixel's first hits toward one light).
  void occluded_coherent(std::span<const Ray> rays, bool* blocked) const;
  // The committed Embree scene, for measurements against bare Embree queries (bench/); rendering
  // goes through intersect and occluded. Queries on it must pass a FiberQueryContext
  // (embree_context.h) when the scene has fibers: their filter functions read it.
  RTCSceneTy* embree_scene() const;

  // The BSDF of a hit's material (per mesh, or per fiber of a curve set).
  const Bsdf& bsdf(const SurfaceHit& hit) const;
  // The material as the renderer shades it at the hit (bound_bsdf.h): bsdf(hit), bound to the
  // hit's place in the weave (its uv) where the mesh is at its weave level.
  BoundBsdf bsdf_at(const SurfaceHit& hit) const {
    const Bsdf& b = bsdf(hit);
    if (weave_on_.empty() || hit.on_fiber() || !weave_on_[hit.shape]) return {&b, nullptr, {}};
    const TableWeave& w = *weave_on_[hit.shape];
    return {&b, w.modulation.get(), w.modulation->locate(hit.uv, w.uv_metres)};
  }

  // Meshes whose material is a fabric_table with a weave (weave_modulation.h), in mesh order,
  // for the choice of their level before a render (integrators weave_level.h).
  struct WovenMesh {
    uint32_t shape = 0;
    std::string name;  // the mesh's first name, or "mesh <index>"
    const TableWeave* weave = nullptr;
    Bounds3 bounds;  // world, every placement (mesh_shifts) included
  };
  const std::vector<WovenMesh>& woven_meshes() const { return woven_; }
  // Whether woven mesh k (of woven_meshes()) is shaded at its weave level. As built: those whose
  // level is "weave"; "auto" and "table" start at the table level.
  bool weave_level(size_t k) const;
  // The same scene with woven mesh k at its weave level where weave_on[k] (one flag per
  // woven_meshes() entry), the table level elsewhere. Error unless the sizes agree.
  RenderScene with_weave_levels(const std::vector<uint8_t>& weave_on) const;
  // Whether a spectral render can draw this scene: weft::Error naming the description's file and
  // the field of the first material without spectral values (bsdfs.h spectral_obstacle), or a
  // light whose colour is not grey (an RGB colour is not a spectrum; grey is one, the same at
  // every wavelength).
  void check_spectral() const;

  // Fibers, for instruments that trace against them (the fabric estimator): how many, the segment
  // a fiber hit lies on (its axis end points and radii: where a line through the fiber leaves it,
  // curves.h cylinder_exit_distance), and every segment of one fiber, in order along it.
  size_t fiber_count() const;
  FiberSegment fiber_segment(const SurfaceHit& hit) const;  // Error unless hit.on_fiber()
  std::vector<FiberSegment> fiber_segments(int64_t fiber) const;
  // The curve set and the curve within it of a fiber id; Error when out of range.
  struct FiberRef {
    uint32_t shape = 0;  // meshes.size() + curve set
    uint32_t curve_set = 0, curve = 0;
  };
  FiberRef fiber_ref(int64_t fiber) const;
  FiberGeometry fiber_geometry() const;

  const std::vector<Light>& lights() const { return lights_; }
  // The light a shape's surface belongs to; null when it does not emit (fibers never do).
  const Light* surface_light(uint32_t shape) const;
  // The same scene lit by 'lights' instead of the description's (emissive surfaces still emit).
  RenderScene with_lights(const Lights& lights) const;
  // The same scene with intersect_coherent and occluded_coherent answering through Embree's
  // packet queries (on: the default, where the Embree library has them) or one ray at a time
  // (off). Every answer, and so every image, is the same bits either way; what packets buy
  // depends on the machine (docs/PERFORMANCE.md), and `weft bench render` measures it.
  RenderScene with_ray_packets(bool on) const;
  bool ray_packets() const { return packets_; }

  size_t mesh_count() const;
  size_t shape_count() const;          // meshes, then curve sets (SurfaceHit::shape)
  size_t triangle_count() const;       // meshes' triangles and the fibers' tube triangles
  size_t curve_segment_count() const;  // round curve segments (0 when fibers are tubes)
  bool cancelled() const;              // the build was stopped (build_progress); do not trace
  Bounds3 bounds() const;

 private:
  struct Geometry;
  class Builder;  // makes the Geometry (render_scene.cpp)
  // What an Embree query reports of a hit: geometry, first-level instance and primitive IDs, the
  // barycentrics or curve parameter, the distance.
  struct EmbreeHit {
    unsigned geom = 0, inst = 0, prim = 0;
    float u = 0, v = 0, t = 0;
  };
  // Fills every field of *hit for 'ray''s hit h.
  void record_hit(const Ray& ray, const EmbreeHit& h, SurfaceHit* hit) const;
  // The end segments of fiber 'ignore_fiber' that a ray leaving it must not meet (none for
  // kNoFiber), for its query context.
  std::optional<FiberEnds> fiber_ends(int64_t ignore_fiber) const;
  RenderScene() = default;
  void set_lights(const Lights& lights);
  // woven_ and the levels as built (render_scene_weave.cpp).
  void find_woven_meshes(const SceneDescription& desc);
  std::shared_ptr<const Geometry> geo_;
  bool packets_ = false;  // coherent queries go to Embree as packets (with_ray_packets)
  std::vector<WovenMesh> woven_;
  // Per mesh: its weave when at the weave level, else null; empty when none is (the common case:
  // bsdf_at then tests one size).
  std::vector<const TableWeave*> weave_on_;
  std::vector<Light> lights_;
  int surface_light_ = -1;  // index of the area light in lights_
};

}  // namespace weft
