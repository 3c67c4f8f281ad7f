#pragma once
// Equal-area mapping between the unit square and the unit sphere (Clarberg's octahedral
// construction, as used by pbrt-v4): each cell of an N x N grid on the square covers the same
// solid angle 4*pi/N^2, which makes it the natural parameterization of tabulated BSDFs.
#include "weft/core/vec.h"

namespace weft {

// p in [0,1]^2 -> unit vector.
Vec3 equal_area_square_to_sphere(Vec2 p);
// Unit vector -> p in [0,1]^2 (inverse of the above).
Vec2 equal_area_sphere_to_square(const Vec3& d);

}  // namespace weft
