#include "weft/integrators/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"

namespace weft {
namespace {

// Power heuristic with exponent 2 (Veach 1997, eq. 9.13) for one sample of each strategy.
double power_heuristic(double pdf_a, double pdf_b) {
  const double a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0 ? a / (a + b) : 0;
}

bool finite(const Rgb& c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

}  // namespace

Rgb trace_path(const RenderScene& scene, const Ray& camera_ray, const RenderSettings& settings,
               Rng& rng, RayCounts& rays, int64_t* first_mesh, const RayObserver* on_ray) {
  auto occluded = [&](const Vec3& o, const Vec3& d, double tmax, int64_t ignore_fiber) {
    ++rays.shadow;
    if (on_ray) (*on_ray)({o, d, tmax}, true);
    return scene.occluded(o, d, tmax, ignore_fiber);
  };
  const bool use_mis = settings.sampling == LightSampling::mis;
  const bool nee_area = settings.sampling != LightSampling::bsdf_only;
  Rgb L(0.0), beta(1.0);
  Ray ray = camera_ray;
  bool specular = true;  // camera rays and delta bounces are not covered by next-event estimation
  double prev_pdf = 0;
  if (first_mesh) *first_mesh = -1;
  // Rays that leave a fiber pass through it (its own fiber never occludes a point of it).
  int64_t ignore_fiber = kNoFiber;
  // Shadow ray from just off the surface (on the target's side) to just short of the target.
  auto occluded_between = [&](const SurfaceHit& h, const Vec3& target) {
    const Vec3 o = h.spawn_origin(target - h.p);
    const Vec3 to = target - o;
    const double d = length(to);
    return d > 0 && occluded(o, to / d, d * (1 - 1e-5), h.fiber);
  };
  // Radiance from a light that the last BSDF sample found, weighted against next-event estimation
  // of the same light.
  auto add_found_light = [&](const Light& light, const LightHit& at) {
    const Rgb Le = light.eval(at);
    if (Le.is_black()) return;
    double w = 1;
    if (!specular) w = use_mis ? power_heuristic(prev_pdf, light.pdf(at)) : (nee_area ? 0.0 : 1.0);
    L += beta * Le * w;
  };

  for (int depth = 0;; ++depth) {
    SurfaceHit hit;
    if (on_ray) (*on_ray)(ray, false);
    const bool found = scene.intersect(ray, &hit, ignore_fiber);
    if (!found) {
      const LightHit escaped = LightHit::escaped_along(ray.d);
      for (const Light& light : scene.lights()) add_found_light(light, escaped);
      break;
    }
    if (depth == 0 && first_mesh) *first_mesh = hit.shape;
    const Vec3 wo_world = -ray.d;
    if (const Light* light = scene.surface_light(hit.shape))
      add_found_light(*light, LightHit::on_surface(ray.d, hit.shape, hit.prim, hit.ng, hit.t));
    if (depth >= settings.max_depth) break;

    const Bsdf& bsdf = scene.bsdf(hit);
    const Frame& frame = hit.shading;
    const Vec3 wo = frame.to_local(wo_world);
    // Shading normals differ from the facets: a direction the BSDF treats as reflection may lie
    // behind the facet (or the reverse for transmission). Such directions would leak light
    // through the surface, so they carry none (Veach 1997, section 5.3). A fiber has no such
    // surface to leak through: it is shaded as a whole, light from any side of B included.
    const double wo_ng = dot(wo_world, hit.ng);
    auto consistent = [&](const Vec3& wi_world, const Vec3& wi_local) {
      return hit.on_fiber() || (wo_ng * dot(wi_world, hit.ng) > 0) == (wo.z * wi_local.z > 0);
    };

    // Next-event estimation: one sample of every light; area lights and the environment weighted
    // against BSDF sampling (lights.h states what a sample holds).
    for (const Light& light : scene.lights()) {
      const bool delta = light.is_delta();
      if (!delta && !nee_area) continue;
      const std::optional<LightSample> ls = light.sample(hit.p, rng);
      if (!ls) continue;
      const Vec3 wi = frame.to_local(ls->wi);
      // Shadow terminator (Hanika 2021, render_scene.h SurfaceHit::lift_front): on a low-poly
      // mesh with vertex normals, the shading normal sees lights that the flat facet has behind
      // it, or that a neighbouring facet hides, and Veach's rule (consistent) then blackens whole
      // facets along the terminator. For reflection, the shadow ray starts instead on the smooth
      // surface the vertex normals describe, above the facet, and decides alone: light that the
      // facet really hides still meets it there, so nothing leaks through.
      const Vec3 lift = wo_ng >= 0 ? hit.lift_front : hit.lift_back;
      const bool lifted = !hit.on_fiber() && wo.z * wi.z > 0 && !(lift == Vec3{});
      const bool agrees = consistent(ls->wi, wi);
      if (!lifted && !agrees) continue;
      const Rgb f = bsdf.eval(wo, wi);
      if (f.is_black()) continue;
      // BSDF sampling stops at directions the facet disagrees on, so there this is the only
      // strategy and takes the whole weight.
      const double w =
          delta || !use_mis || !agrees ? 1.0 : power_heuristic(ls->pdf, bsdf.pdf(wo, wi));
      bool blocked;
      if (lifted) {
        // Off the lifted point on the viewer's side of the facet.
        const Vec3 o = hit.p + lift + hit.ng * (wo_ng >= 0 ? hit.offset : -hit.offset);
        if (ls->at_infinity) {
          blocked = occluded(o, ls->wi, 1e300, hit.fiber);
        } else {
          const Vec3 to = ls->p_light - o;
          const double d = length(to);
          blocked = !(d > 0) || occluded(o, to / d, d * (1 - 1e-5), hit.fiber);
        }
      } else {
        blocked = ls->at_infinity ? occluded(hit.spawn_origin(ls->wi), ls->wi, 1e300, hit.fiber)
                                  : occluded_between(hit, ls->p_light);
      }
      if (!blocked) L += beta * f * ls->L * (std::abs(wi.z) * (w * ls->falloff) / ls->pdf);
    }

    // Continue the path by sampling the BSDF.
    const double u_lobe = rng.uniform();
    const Vec2 u{rng.uniform(), rng.uniform()};
    const auto bs = bsdf.sample(wo, u, u_lobe);
    if (!bs || bs->weight.is_black() || !(bs->pdf > 0 || bs->is_delta)) break;
    const Vec3 wi = normalize(frame.to_world(bs->wi));
    if (!consistent(wi, bs->wi)) break;
    beta *= bs->weight;
    specular = bs->is_delta;
    prev_pdf = bs->pdf;
    ray = {hit.spawn_origin(wi), wi};
    ignore_fiber = hit.fiber;
    ++rays.bounce;
    if (depth + 1 >= settings.rr_depth) {
      const double q = std::min(0.95, beta.max_component());
      if (!(rng.uniform() < q)) break;
      beta = beta / q;
    }
  }
  return L;
}

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
                    const ProgressCallback& progress, const RenderObservers& observers) {
  if (s.width < 1 || s.height < 1 || s.spp < 1 || s.tile_size < 1 || s.max_depth < 0 ||
      s.rr_depth < 0)
    throw Error("", "render", "width, height, spp and tile size must be positive");
  RenderResult out;
  out.image = Image(s.width, s.height);
  const RayObserver* on_ray = observers.on_ray ? &observers.on_ray : nullptr;
  const int tx = (s.width + s.tile_size - 1) / s.tile_size,
            ty = (s.height + s.tile_size - 1) / s.tile_size;
  const uint64_t tiles = uint64_t(tx) * ty;
  std::vector<RayCounts> tile_rays(tiles);
  std::vector<uint64_t> tile_nonfinite(tiles, 0);
  std::atomic<bool> cancel{false};
  std::atomic<uint64_t> done{0};
  std::mutex progress_mutex;
  const double aspect = double(s.width) / s.height;
  const double inv_spp = 1.0 / s.spp;

  parallel_for(tiles, s.threads, [&](uint64_t tile) {
    if (cancel.load(std::memory_order_relaxed)) return;
    const int x0 = int(tile % tx) * s.tile_size, y0 = int(tile / tx) * s.tile_size;
    const int x1 = std::min(x0 + s.tile_size, s.width), y1 = std::min(y0 + s.tile_size, s.height);
    RayCounts rays;
    for (int y = y0; y < y1; ++y) {
      // A cancelled render is discarded anyway: stop within a row, not a whole tile.
      if (cancel.load(std::memory_order_relaxed)) return;
      for (int x = x0; x < x1; ++x) {
        const uint64_t pixel = uint64_t(y) * s.width + x;
        double sum[3] = {0, 0, 0};
        for (int k = 0; k < s.spp; ++k) {
          Rng rng(s.seed, pixel, uint64_t(k));
          const double fx = (x + rng.uniform()) / s.width, fy = (y + rng.uniform()) / s.height;
          const Ray ray = camera.generate_ray(fx, fy, aspect);
          ++rays.camera;
          int64_t first = -1;
          Rgb L = trace_path(scene, ray, s, rng, rays, &first, on_ray);
          if (!finite(L)) {
            ++tile_nonfinite[tile];
            L = Rgb(0.0);
          }
          sum[0] += L.r, sum[1] += L.g, sum[2] += L.b;
          if (observers.on_sample) observers.on_sample(pixel, first, L);
        }
        for (int i = 0; i < 3; ++i)
          out.image.rgb[3 * pixel + i] = static_cast<float>(sum[i] * inv_spp);
      }
    }
    tile_rays[tile] = rays;
    const uint64_t d = done.fetch_add(1) + 1;
    std::lock_guard lock(progress_mutex);
    if (!cancel.load() && !progress({"render", d, tiles})) cancel.store(true);
  });
  for (uint64_t t = 0; t < tiles; ++t) {
    out.rays += tile_rays[t];
    out.nonfinite_samples += tile_nonfinite[t];
  }
  out.cancelled = cancel.load();
  return out;
}

}  // namespace weft
