#pragma once
// The immutable, renderable form of a SceneDescription: an Embree 3 scene committed once, one BSDF
// per material binding (created once through the material registry), and its lights (lights.h):
// the description's, plus the emissive triangles as one area light. Copies share the geometry;
// with_lights() swaps the description's lights without rebuilding anything. Thread-safe for
// concurrent queries.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/frame.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/lights.h"
#include "weft/scenes/mesh.h"

struct RTCSceneTy;  // Embree's scene (RTCScene is a pointer to it)

namespace weft {

struct SurfaceHit {
  double t = 0;
  Vec3 p;         // position (barycentric interpolation, double precision)
  Vec3 ng;        // unit geometric normal, front side = counter-clockwise winding
  Frame shading;  // shading normal (z) and tangent (x) from the mesh; not flipped
  Vec2 uv;
  uint32_t mesh = 0;  // index into the description's meshes
  uint32_t prim = 0;  // triangle index
  double offset = 0;  // distance to move ray origins off the surface (scales with coordinates)

  // Origin for a ray leaving the surface in direction d: offset along ng to d's side, so rays
  // continue through the surface for transmission and do not re-hit it.
  Vec3 spawn_origin(const Vec3& d) const { return p + ng * (dot(d, ng) > 0 ? offset : -offset); }
};

struct RenderSceneOptions {
  // Material keys replaced by another binding (e.g. the white reference of the gonioreflectometer).
  std::vector<uint8_t> override_meshes;  // per mesh; empty = none
  std::optional<MaterialBinding> override_binding;
  // Tables (fiber/fabric BSDFs, measured networks) are loaded once into this cache and shared
  // between bindings and between scenes that pass the same cache; null: one cache per scene.
  std::shared_ptr<TableCache> table_cache;
  // Fiber tables a material names by spec: who makes them (null: "spec" is an error) and the
  // progress of that work.
  FiberTableResolver fiber_tables;
  ProgressCallback material_progress = no_progress();
};

class RenderScene {
 public:
  explicit RenderScene(const SceneDescription& desc, const RenderSceneOptions& options = {});

  bool intersect(const Ray& ray, SurfaceHit* hit) const;
  bool occluded(const Vec3& origin, const Vec3& dir, double tmax) const;
  // The committed Embree scene, for measurements against bare Embree queries (bench/); rendering
  // goes through intersect and occluded.
  RTCSceneTy* embree_scene() const;

  const Bsdf& bsdf(uint32_t mesh) const;

  // Every light, in the order their contributions are summed: parallel, point and spot (in the
  // description's order), the emissive surfaces, the environment. Lights that cannot contribute
  // (no emissive triangle, a black environment) are left out.
  const std::vector<Light>& lights() const { return lights_; }
  // The light a mesh's surface belongs to; null when the mesh does not emit.
  const Light* surface_light(uint32_t mesh) const;
  // The same scene lit by 'lights' instead of the description's (emissive surfaces still emit).
  RenderScene with_lights(const Lights& lights) const;

  size_t mesh_count() const;
  size_t triangle_count() const;
  Bounds3 bounds() const;

 private:
  struct Geometry;
  RenderScene() = default;
  void set_lights(const Lights& lights);
  std::shared_ptr<const Geometry> geo_;
  std::vector<Light> lights_;
  int surface_light_ = -1;  // index of the area light in lights_
};

}  // namespace weft
