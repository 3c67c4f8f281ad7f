#pragma once
// Built-in primitives: the inline objects of a scene description (description.h) and the scenes
// that code builds in memory (the bundled examples use glTF files).
#include "weft/scenes/mesh.h"

namespace weft {

// A w x h rectangle centred at 'center' facing 'normal', its first side along 'tangent'.
TriangleMesh make_quad(const Vec3& center, const Vec3& normal, const Vec3& tangent, double w,
                       double h);
// An icosphere (subdivided icosahedron, vertices on the sphere) facing outwards, or inwards.
TriangleMesh make_sphere(const Vec3& center, double radius, int subdivisions, bool inward);

}  // namespace weft
