#pragma once
// The scattering of one straight fiber, measured by rendering it: the fiber's counterpart of the
// gonioreflectometer (gonio.h). Under a parallel light of irradiance E from w_i, an orthographic
// film facing w_o sums the radiance of the fiber length l it sees: sum L A_px = I(w_o) l / l_fiber,
// the radiant intensity of that length, and
//   F(w_i, w_o) = I / (E l R) = sum L A_px / (E l R),
// the fiber's scattering per unit length in fiber radii (docs/fiber-bsdf.md): the integral over
// the circumference angle of f |cos theta_i| cos+ theta_o, the quantity of the baker's far-field
// tally (fiber_bake.h). The film's width runs along the fiber's projection, so it sees the length
// l = width / sqrt(1 - s_o^2) of a fiber uniform along its axis, for any width.
#include <cstdint>

#include "weft/core/vec.h"
#include "weft/integrators/render_settings.h"
#include "weft/scenes/render_scene.h"

namespace weft {

// A straight fiber of the scene: a point on its axis, the unit axis and the radius (metres).
// Nothing else of the scene may come into the film (2 film_radii x film_length_radii radii
// around the axis point, seen from w_o), the fiber must reach past the film's ends, and the film
// plane, distance_radii from the axis point towards w_o, must lie outside the scene.
struct FiberScatteringSetup {
  Vec3 center, axis{1, 0, 0};
  double radius = 1;
  double film_length_radii = 16, film_radii = 1.25, distance_radii = 1000;
  int width = 32, height = 8;  // pixels: along the fiber, across it
  int spp = 16;
  uint64_t seed = 0;
  int threads = 0;
};

struct FiberScatteringEstimate {
  double value = 0;      // F (the green channel)
  double std_error = 0;  // from each pixel's sample variance
};

// F(w_i, w_o) of the fiber, w_i towards the light and w_o towards the viewer (unit, world), from
// a render of 'scene' lit by one parallel light alone (direct light: max_depth 1).
FiberScatteringEstimate render_fiber_scattering(const RenderScene& scene,
                                                const FiberScatteringSetup& setup, const Vec3& w_i,
                                                const Vec3& w_o);

// The unit direction with axial cosine s and azimuth psi about 'axis', psi measured from
// 'reference' (perpendicular to the axis) towards axis x reference: with axis x and reference y,
// the baker's world frame (psi = atan2(z, y)).
Vec3 fiber_direction(const Vec3& axis, const Vec3& reference, double s, double psi);

}  // namespace weft
