#pragma once
// Fibers as Embree round curves against triangle tubes (FiberGeometry, render_scene.h), on the
// same fibers: build time, rays per second (RenderScene::intersect on rays leaving fiber
// surfaces with their own fiber ignored, as the path tracer's bounces; and the path tracer's own
// rays on a fiber-level woven patch), and the accuracy of a one-fiber render: a Lambertian fiber
// under parallel light (fiber_scattering.h) against its closed form,
//   F = (rho / pi) sqrt(1 - s_i^2) sqrt(1 - s_o^2) ((pi - a) cos a + sin a) / 2,
// the integral over the circumference of cos+ theta_i cos+ theta_o (s: axial cosines, a: the
// azimuth between the directions). Timing lives here and in bench/, never in unit tests.
#include <cstddef>
#include <string>
#include <vector>

#include "weft/integrators/render_settings.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/weave.h"

namespace weft {

struct FiberBenchOptions {
  WeaveOptions weave;             // the patch; unset fields: red cotton (fiber detail is forced)
  size_t rays = size_t(1) << 18;  // incoherent rays from fiber surfaces
  int threads = 2;
  RenderSettings render;  // of the patch (its threads replaced by 'threads')
  // Representations measured, in order (FiberGeometry::Type::curves, tubes of n sides).
  std::vector<FiberGeometry> geometries;
  int accuracy_spp = 64;  // per pixel of each one-fiber render (32 x 8 pixels)
  FiberBenchOptions();
};

struct FiberBenchRow {
  std::string geometry;  // "curves" or "tubes:N"
  size_t fibers = 0, curve_segments = 0, triangles = 0;
  double build_s = 0;
  double rays_per_s = 0;       // intersect(), own fiber ignored, 'threads' threads
  double hit_fraction = 0;     // of those rays (the same rays for every representation)
  double path_rays_per_s = 0;  // every ray of the path tracer on the patch
  // One Lambertian fiber over a fixed set of direction pairs (36: light and view at axial cosines
  // -0.5..0.6, azimuth differences 0..140 deg), rendered F_r against the closed form F_e:
  // total: sum F_r / sum F_e - 1 (the light scattered, all pairs together); rms: the relative L2
  // error sqrt(sum (F_r - F_e)^2 / sum F_e^2); noise: the renders' own, in the rms's units.
  double one_fiber_total_error = 0, one_fiber_rms_error = 0, one_fiber_noise = 0;
};

std::vector<FiberBenchRow> bench_fibers(const FiberBenchOptions& options);

}  // namespace weft
