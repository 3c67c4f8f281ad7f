#pragma once
// The immutable, renderable form of a SceneDescription: an Embree 3 scene committed once, one BSDF
// per material binding (created once through the material registry), emissive triangles as area
// lights, and the non-geometric lights. Copies share the geometry; with_lights() swaps the
// lights without rebuilding anything. Thread-safe for concurrent queries.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/distribution.h"
#include "weft/core/frame.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/description.h"
#include "weft/scenes/lights.h"
#include "weft/scenes/mesh.h"

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

struct AreaLightSample {
  Vec3 p, n;            // point on the emitter, its unit geometric normal
  uint32_t mesh = 0;    // emitted(mesh, n, w) gives its radiance towards w
  double pdf_area = 0;  // density w.r.t. area of the chosen point
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
  // Bare rtcIntersect1: hit distance or infinity, no surface reconstruction (for benchmarks).
  double intersect_distance(const Ray& ray) const;

  const Bsdf& bsdf(uint32_t mesh) const;
  // Radiance emitted by the mesh towards w (unit, pointing away from the surface).
  Rgb emitted(uint32_t mesh, const Vec3& ng, const Vec3& w) const;
  bool has_area_lights() const;
  // Samples an emissive triangle by power and a point on it uniformly.
  AreaLightSample sample_area_light(double u_pick, Vec2 u) const;
  // Area density with which sample_area_light picks a point on (mesh, prim).
  double area_light_pdf(uint32_t mesh, uint32_t prim) const;

  const Lights& lights() const { return lights_; }
  RenderScene with_lights(Lights lights) const;

  size_t mesh_count() const;
  size_t triangle_count() const;
  Bounds3 bounds() const;

 private:
  struct Geometry;
  RenderScene() = default;
  std::shared_ptr<const Geometry> geo_;
  Lights lights_;
};

}  // namespace weft
