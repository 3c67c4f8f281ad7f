#include "weft/integrators/fiber_scattering.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/integrators/masked_render.h"

namespace weft {

FiberScatteringEstimate render_fiber_scattering(const RenderScene& scene,
                                                const FiberScatteringSetup& f, const Vec3& w_i,
                                                const Vec3& w_o) {
  if (!(f.radius > 0) || !(f.film_length_radii > 0) || !(f.film_radii > 0) || f.width < 1 ||
      f.height < 1 || f.spp < 2 || !(f.distance_radii > f.film_radii))
    throw Error("", "fiber scattering", "needs a radius, a film and at least 2 samples per pixel");
  const Vec3 axis = normalize(f.axis);
  const double s_o = dot(axis, w_o);
  if (!(std::abs(s_o) < 1 - 1e-9))
    throw Error("", "fiber scattering", "the view runs along the fiber");
  const double e = 1.0;
  Lights lights;
  lights.directional.push_back({w_i, Rgb(e)});
  const RenderScene lit = scene.with_lights(lights);
  Camera cam;
  cam.type = Camera::Type::orthographic;
  cam.forward = -w_o;
  cam.right = normalize(axis - w_o * s_o);
  cam.up = cross(cam.right, cam.forward);
  cam.position = f.center + w_o * (f.distance_radii * f.radius);
  cam.half_width = 0.5 * f.film_length_radii * f.radius;
  cam.half_height = f.film_radii * f.radius;
  RenderSettings s;
  s.width = f.width;
  s.height = f.height;
  s.spp = f.spp;
  s.max_depth = 1;
  s.seed = f.seed;
  s.threads = f.threads;
  const MaskedRender m = render_masked(lit, cam, s, std::vector<uint8_t>(scene.shape_count(), 1));
  double sum = 0, var = 0;
  for (size_t p = 0; p < m.coverage.size(); ++p) {
    const double mean = m.sum[3 * p + 1], second = m.sum_sq[3 * p + 1];
    sum += mean;
    var += std::max(0.0, second - mean * mean) / (f.spp - 1);
  }
  const double pixel_area = (2 * cam.half_width / s.width) * (2 * cam.half_height / s.height);
  const double seen = 2 * cam.half_width / std::sqrt(1 - s_o * s_o);
  const double scale = pixel_area / (e * seen * f.radius);
  return {sum * scale, std::sqrt(var) * scale};
}

Vec3 fiber_direction(const Vec3& axis, const Vec3& reference, double s, double psi) {
  const Vec3 t = normalize(axis);
  const Vec3 u = normalize(reference - t * dot(reference, t)), v = cross(t, u);
  const double c = std::sqrt(std::max(0.0, 1 - s * s));
  return t * s + u * (c * std::cos(psi)) + v * (c * std::sin(psi));
}

}  // namespace weft
