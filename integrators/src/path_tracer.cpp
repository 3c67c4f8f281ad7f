#include "weft/integrators/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdfs.h"

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

// Light per band along a spectral render's path.
struct Bands {
  Spectrum v{};
  Bands() = default;
  explicit Bands(double x) { v.fill(x); }
  Bands& operator+=(const Bands& o) {
    for (int b = 0; b < kNumBands; ++b) v[b] += o.v[b];
    return *this;
  }
  Bands& operator*=(const Bands& o) {
    for (int b = 0; b < kNumBands; ++b) v[b] *= o.v[b];
    return *this;
  }
  Bands& operator*=(double s) {
    for (double& x : v) x *= s;
    return *this;
  }
  double max_component() const { return *std::max_element(v.begin(), v.end()); }
  bool is_black() const {
    return std::all_of(v.begin(), v.end(), [](double x) { return x == 0; });
  }
};
Bands operator*(Bands a, const Bands& b) {
  return a *= b;
}
Bands operator*(Bands a, double s) {
  return a *= s;
}
Bands operator/(Bands a, double s) {
  return a *= 1.0 / s;
}

// How a path's colour is shaded: in RGB, or per band (a spectral render, whose lights are grey:
// RenderScene::check_spectral). Directions and light samples are drawn the same way in both (a
// table by its RGB mean); Russian roulette follows the largest value the path carries.
struct RgbShading {
  using Color = Rgb;
  static Rgb f(const Bsdf& b, const Vec3& wo, const Vec3& wi) { return b.eval(wo, wi); }
  static Rgb weight(const Bsdf&, const Vec3&, const BsdfSample& s) { return s.weight; }
  static Rgb light(const Rgb& L) { return L; }
  static Rgb to_rgb(const Rgb& c) { return c; }
};
struct BandShading {
  using Color = Bands;
  static Bands f(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
    Bands out;
    eval_bands(b, wo, wi, out.v);
    return out;
  }
  static Bands weight(const Bsdf& b, const Vec3& wo, const BsdfSample& s) {
    Bands out;
    sample_weight_bands(b, wo, s, out.v);
    return out;
  }
  static Bands light(const Rgb& L) { return Bands(L.r); }
  static Rgb to_rgb(const Bands& c) {
    return bands_to_linear_srgb([&c](int b) { return c.v[b]; });
  }
};

template <class Shading>
Rgb trace(const RenderScene& scene, const Ray& camera_ray, const RenderSettings& settings, Rng& rng,
          RayCounts& rays, int64_t* first_mesh, const RayObserver* on_ray) {
  using Color = typename Shading::Color;
  auto occluded = [&](const Vec3& o, const Vec3& d, double tmax, int64_t ignore_fiber) {
    ++rays.shadow;
    if (on_ray) (*on_ray)({o, d, tmax}, true);
    return scene.occluded(o, d, tmax, ignore_fiber);
  };
  const bool use_mis = settings.sampling == LightSampling::mis;
  const bool nee_area = settings.sampling != LightSampling::bsdf_only;
  Color L(0.0), beta(1.0);
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
    L += beta * Shading::light(Le) * w;
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
      const Color f = Shading::f(bsdf, wo, wi);
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
      if (!blocked)
        L += beta * f * Shading::light(ls->L) * (std::abs(wi.z) * (w * ls->falloff) / ls->pdf);
    }

    // Continue the path by sampling the BSDF.
    const double u_lobe = rng.uniform();
    const Vec2 u{rng.uniform(), rng.uniform()};
    const auto bs = bsdf.sample(wo, u, u_lobe);
    if (!bs || bs->weight.is_black() || !(bs->pdf > 0 || bs->is_delta)) break;
    const Vec3 wi = normalize(frame.to_world(bs->wi));
    if (!consistent(wi, bs->wi)) break;
    const Color weight = Shading::weight(bsdf, wo, *bs);
    if (weight.is_black()) break;
    beta *= weight;
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
  return Shading::to_rgb(L);
}

}  // namespace

Rgb trace_path(const RenderScene& scene, const Ray& ray, const RenderSettings& settings, Rng& rng,
               RayCounts& rays, int64_t* first_mesh, const RayObserver* on_ray) {
  return settings.spectral ? trace<BandShading>(scene, ray, settings, rng, rays, first_mesh, on_ray)
                           : trace<RgbShading>(scene, ray, settings, rng, rays, first_mesh, on_ray);
}

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
                    const ProgressCallback& progress, const RenderObservers& observers) {
  if (s.width < 1 || s.height < 1 || s.spp < 1 || s.tile_size < 1 || s.max_depth < 0 ||
      s.rr_depth < 0)
    throw Error("", "render", "width, height, spp and tile size must be positive");
  if (!(s.time_limit_s >= 0) || !std::isfinite(s.time_limit_s))
    throw Error("", "render.time_limit_s", "must be a finite number of seconds >= 0");
  const PixelWindow win = s.crop.value_or(PixelWindow{0, s.width, 0, s.height});
  check_crop(win, s.width, s.height, "", "render.crop");
  if (s.spectral) scene.check_spectral();
  RenderResult out;
  const int ww = win.width(), wh = win.height();
  const size_t npx = size_t(ww) * wh;
  auto film_image = [&] {
    Image im(ww, wh);
    im.x0 = win.x0, im.y0 = win.y0, im.film_width = s.width, im.film_height = s.height;
    return im;
  };
  out.image = film_image();
  const bool aov = s.aov_albedo || s.aov_normal;
  if (s.aov_albedo) out.albedo = film_image();
  if (s.aov_normal) out.normal = film_image();
  const RayObserver* on_ray = observers.on_ray ? &observers.on_ray : nullptr;
  const int tx = (ww + s.tile_size - 1) / s.tile_size, ty = (wh + s.tile_size - 1) / s.tile_size;
  const uint64_t tiles = uint64_t(tx) * ty;
  std::vector<RayCounts> tile_rays(tiles);
  std::vector<uint64_t> tile_nonfinite(tiles, 0);
  std::atomic<bool> cancel{false};
  std::atomic<uint64_t> done{0};
  const uint64_t total = uint64_t(npx) * s.spp;
  std::mutex progress_mutex;
  const double aspect = double(s.width) / s.height;

  // Per-pixel sums of radiance, albedo and normal, in sample order.
  struct Sums {
    double L[3] = {0, 0, 0}, albedo[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
  };
  // Samples [k0, k1) of film pixel (x, y), added to 'acc'.
  auto sample_pixel = [&](int x, int y, int k0, int k1, Sums& acc, RayCounts& rays,
                          uint64_t& nonfinite) {
    const uint64_t pixel = uint64_t(y) * s.width + x;
    for (int k = k0; k < k1; ++k) {
      Rng rng(s.seed, pixel, uint64_t(k));
      const double fx = (x + rng.uniform()) / s.width, fy = (y + rng.uniform()) / s.height;
      const Ray ray = camera.generate_ray(fx, fy, aspect);
      ++rays.camera;
      int64_t first = -1;
      Rgb L = trace_path(scene, ray, s, rng, rays, &first, on_ray);
      if (!finite(L)) {
        ++nonfinite;
        L = Rgb(0.0);
      }
      acc.L[0] += L.r, acc.L[1] += L.g, acc.L[2] += L.b;
      if (observers.on_sample) observers.on_sample(pixel, first, L);
      if (aov) {
        // Its own stream (the sample index with the top bit set, never a render sample), so
        // asking for passes leaves the image's bits alone.
        Rng aov_rng(s.seed, pixel, uint64_t(k) | (uint64_t(1) << 63));
        SurfaceHit hit;
        if (!scene.intersect(ray, &hit, kNoFiber)) continue;
        const Vec3 wo_world = -ray.d;
        if (s.aov_normal) {
          const Vec3 n = dot(hit.shading.n, wo_world) < 0 ? -hit.shading.n : hit.shading.n;
          acc.normal[0] += n.x, acc.normal[1] += n.y, acc.normal[2] += n.z;
        }
        if (s.aov_albedo) {
          const Vec3 wo = hit.shading.to_local(wo_world);
          const double u_lobe = aov_rng.uniform();
          const Vec2 u{aov_rng.uniform(), aov_rng.uniform()};
          const Bsdf& bsdf = scene.bsdf(hit);
          const auto bs = bsdf.sample(wo, u, u_lobe);
          if (bs && finite(bs->weight)) {
            const Rgb a =
                s.spectral ? BandShading::to_rgb(BandShading::weight(bsdf, wo, *bs)) : bs->weight;
            acc.albedo[0] += a.r, acc.albedo[1] += a.g, acc.albedo[2] += a.b;
          }
        }
      }
    }
  };
  auto store = [&](size_t i, const Sums& acc, double inv_n) {
    for (int c = 0; c < 3; ++c) {
      out.image.rgb[3 * i + c] = static_cast<float>(acc.L[c] * inv_n);
      if (s.aov_albedo) out.albedo.rgb[3 * i + c] = static_cast<float>(acc.albedo[c] * inv_n);
      if (s.aov_normal) out.normal.rgb[3 * i + c] = static_cast<float>(acc.normal[c] * inv_n);
    }
  };
  // Samples [k0, k1) of every pixel of the window, tile by tile; 'sums' holds the running sums
  // when the render goes in several passes (null: one pass, stored as it ends).
  auto pass = [&](int k0, int k1, std::vector<Sums>* sums) {
    parallel_for(tiles, s.threads, [&](uint64_t tile) {
      if (cancel.load(std::memory_order_relaxed)) return;
      const int x0 = int(tile % tx) * s.tile_size, y0 = int(tile / tx) * s.tile_size;
      const int x1 = std::min(x0 + s.tile_size, ww), y1 = std::min(y0 + s.tile_size, wh);
      RayCounts rays;
      for (int y = y0; y < y1; ++y) {
        // A cancelled render is discarded anyway: stop within a row, not a whole tile.
        if (cancel.load(std::memory_order_relaxed)) return;
        for (int x = x0; x < x1; ++x) {
          const size_t i = size_t(y) * ww + x;
          if (sums) {
            sample_pixel(win.x0 + x, win.y0 + y, k0, k1, (*sums)[i], rays, tile_nonfinite[tile]);
          } else {
            Sums acc;
            sample_pixel(win.x0 + x, win.y0 + y, k0, k1, acc, rays, tile_nonfinite[tile]);
            store(i, acc, 1.0 / s.spp);
          }
        }
      }
      tile_rays[tile] += rays;
      const uint64_t d = done.fetch_add(uint64_t(x1 - x0) * (y1 - y0) * (k1 - k0)) +
                         uint64_t(x1 - x0) * (y1 - y0) * (k1 - k0);
      std::lock_guard lock(progress_mutex);
      if (!cancel.load() && !progress({"render", d, total, "samples"})) cancel.store(true);
    });
  };

  if (s.time_limit_s == 0) {
    pass(0, s.spp, nullptr);
    out.spp_done = s.spp;
  } else {
    // One sample per pixel a pass, so that the image is always a whole number of samples per
    // pixel; the sums are kept between passes (72 bytes a pixel).
    const auto start = std::chrono::steady_clock::now();
    std::vector<Sums> sums(npx);
    int n = 0;
    while (n < s.spp && !cancel.load()) {
      pass(n, n + 1, &sums);
      if (cancel.load()) break;
      ++n;
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (elapsed >= s.time_limit_s) break;
    }
    out.spp_done = n;
    if (n > 0)
      for (size_t i = 0; i < npx; ++i) store(i, sums[i], 1.0 / n);
  }
  for (uint64_t t = 0; t < tiles; ++t) {
    out.rays += tile_rays[t];
    out.nonfinite_samples += tile_nonfinite[t];
  }
  out.cancelled = cancel.load();
  return out;
}

}  // namespace weft
