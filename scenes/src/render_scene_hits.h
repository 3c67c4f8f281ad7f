#pragma once
// The surface at a RenderScene hit (render_scene.cpp's queries fill SurfaceHit with these).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "weft/scenes/render_scene.h"

namespace weft {

// The mesh's vertex normals made unit in double precision (zero where a normal is degenerate),
// once per scene: every hit's shadow-terminator lift reads three of them.
// A yarn sample's mesh has tens of millions of vertices: 'keep_going', when given, is asked every
// kUnitNormalsPerPoll of them (a few milliseconds); once it says stop, the rest are left zero.
inline constexpr size_t kUnitNormalsPerPoll = size_t{1} << 20;
std::vector<Vec3> unit_vertex_normals(const TriangleMesh& m,
                                      const std::function<bool()>& keep_going = {});

// Fills the hit on triangle 'prim' of 'm' (whose unit_vertex_normals are 'unit_normals'), moved
// by 'shift' (null: in place), at barycentrics (b1, b2).
void triangle_hit(const TriangleMesh& m, const std::vector<Vec3>& unit_normals, uint32_t prim,
                  double b1, double b2, const Ray& ray, SurfaceHit* hit,
                  const Vec3* shift = nullptr);

// Fills the hit on a round curve segment from Embree's distance: the point is put back onto the
// fiber's surface (radially from the axis point closest to the ray's point), in double precision.
void curve_hit(const FiberSegment& s, double t, const Ray& ray, SurfaceHit* hit);

}  // namespace weft
