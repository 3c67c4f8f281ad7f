#include "weft/integrators/path_tracer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <utility>

#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/weave_level.h"
#include "weft/materials/bound_bsdf.h"
#include "weft/materials/bsdfs.h"
#include "zero_polled.h"

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
  static Rgb f(const BoundBsdf& b, const Vec3& wo, const Vec3& wi) { return b.eval(wo, wi); }
  static Rgb weight(const BoundBsdf&, const Vec3&, const BsdfSample& s) { return s.weight; }
  static Rgb light(const Rgb& L) { return L; }
  static Rgb to_rgb(const Rgb& c) { return c; }
};
struct BandShading {
  using Color = Bands;
  static Bands f(const BoundBsdf& b, const Vec3& wo, const Vec3& wi) {
    Bands out;
    eval_bands(b, wo, wi, out.v);
    return out;
  }
  static Bands weight(const BoundBsdf& b, const Vec3& wo, const BsdfSample& s) {
    Bands out;
    sample_weight_bands(b, wo, s, out.v);
    return out;
  }
  static Bands light(const Rgb& L) { return Bands(L.r); }
  static Rgb to_rgb(const Bands& c) {
    return bands_to_linear_srgb([&c](int b) { return c.v[b]; });
  }
};

// A shading point of a path: the hit, its BSDF (bound to the hit's place in a weave) and the
// direction back along the path.
struct PathVertex {
  const SurfaceHit& hit;
  BoundBsdf bsdf;
  Vec3 wo;       // towards the previous vertex, in the shading frame
  double wo_ng;  // the same direction in the world, dotted with the facet normal

  // Shading normals differ from the facets: a direction the BSDF treats as reflection may lie
  // behind the facet (or the reverse for transmission). Such directions would leak light
  // through the surface, so they carry none (Veach 1997, section 5.3). A fiber has no such
  // surface to leak through: it is shaded as a whole, light from any side of B included.
  bool consistent(const Vec3& wi_world, const Vec3& wi_local) const {
    return hit.on_fiber() || (wo_ng * dot(wi_world, hit.ng) > 0) == (wo.z * wi_local.z > 0);
  }
};

// Whether the caller has found the camera ray's first hit already, into PathTrace::record().
struct KnownFirstHit {
  bool known = false;  // false: the path traces the camera ray itself
  bool found = false;  // whether the ray hits anything (record() holds the hit)
};

// A light sample's contribution to a path and what decides whether it arrives: a shadow ray, or
// nothing (a sample that needs no ray, 'decided' 0 or 1 for unblocked or blocked).
template <class Color>
struct ShadowTest {
  Color contribution = Color(0.0);
  Ray ray;
  int64_t ignore_fiber = kNoFiber;
  int decided = -1;  // -1: trace 'ray'
  int light = 0;     // the light's index in RenderScene::lights
};

// One path from the camera: its radiance so far (L) and throughput (beta). A vertex's light
// samples are collected before their shadow rays are answered, so that a caller may answer the
// first vertex's rays of several paths together (trace_camera_group); their light is added in
// the lights' order either way, so the bits do not depend on it.
template <class Shading>
class PathTrace {
 public:
  using Color = typename Shading::Color;
  // Light samples held at a vertex before their shadow rays are answered; a vertex with more
  // answers the first ones itself, in order.
  static constexpr int kHeldShadows = 4;

  PathTrace(const RenderScene& scene, const RenderSettings& settings, Rng& rng, RayCounts& rays,
            const RayObserver* on_ray)
      : scene_(scene), settings_(settings), rng_(rng), rays_(rays), on_ray_(on_ray) {
    if (settings.light_groups) by_light_.emplace();
  }

  Rgb run(const Ray& camera_ray, int64_t* first_mesh) {
    if (start(camera_ray, first_mesh, {})) {
      answer_shadows(nullptr);
      go_on();
    }
    return result();
  }

  // The first vertex, up to its light samples (held()); false: the path ended before them.
  bool start(const Ray& camera_ray, int64_t* first_mesh, KnownFirstHit first) {
    ray_ = camera_ray;
    if (first_mesh) *first_mesh = -1;
    return vertex(0, first, first_mesh);
  }
  std::span<const ShadowTest<Color>> held() const { return {held_.test, size_t(n_held_)}; }
  // The record the path's hits are written to: the caller may find the first hit into it
  // (then start with KnownFirstHit{true, found}).
  SurfaceHit& record() { return hit_; }
  // Adds the held samples' light: blocked[i] (0 or 1) answers held()[i]'s ray; -1, or a null
  // 'blocked', has it traced here.
  void answer_shadows(const int8_t* blocked) {
    for (int i = 0; i < n_held_; ++i) {
      const ShadowTest<Color>& t = held_.test[i];
      bool b;
      if (t.decided >= 0)
        b = t.decided != 0;
      else if (blocked && blocked[i] >= 0)
        b = blocked[i] != 0;
      else
        b = scene_.occluded(t.ray.o, t.ray.d, t.ray.tmax, t.ignore_fiber);
      if (!b) add(t.light, t.contribution);
    }
    n_held_ = 0;
  }
  // After start() and answer_shadows(): the rest of the path, a vertex at a time.
  void go_on() {
    for (int depth = 0; extend(*vertex_, depth) && vertex(depth + 1, {}, nullptr); ++depth)
      answer_shadows(nullptr);
  }
  Rgb result() const { return Shading::to_rgb(L_); }
  // With light groups: light k's share of result() into out[k], for every light of the scene.
  void light_results(Rgb* out) const {
    for (size_t k = 0; k < scene_.lights().size(); ++k) out[k] = Shading::to_rgb((*by_light_)[k]);
  }

 private:
  // The vertex at 'depth' along ray_: the light its ray finds (a surface light, or the lights at
  // infinity where it escapes) and its light samples, held. False: the path ends here.
  bool vertex(int depth, KnownFirstHit first, int64_t* first_mesh) {
    if (on_ray_) (*on_ray_)(ray_, false);
    bool found;
    if (first.known)
      found = first.found;
    else
      found = scene_.intersect(ray_, &hit_, ignore_fiber_);
    if (!found) {
      const LightHit escaped = LightHit::escaped_along(ray_.d);
      for (size_t k = 0; k < scene_.lights().size(); ++k)
        add_found_light(static_cast<int>(k), escaped);
      return false;
    }
    if (first_mesh) *first_mesh = hit_.shape;
    const Vec3 wo_world = -ray_.d;
    if (const Light* light = scene_.surface_light(hit_.shape))
      add_found_light(static_cast<int>(light - scene_.lights().data()),
                      LightHit::on_surface(ray_.d, hit_.shape, hit_.prim, hit_.ng, hit_.t));
    if (depth >= settings_.max_depth) return false;
    vertex_.emplace(PathVertex{hit_, scene_.bsdf_at(hit_), hit_.shading.to_local(wo_world),
                               dot(wo_world, hit_.ng)});
    sample_lights(*vertex_);
    return true;
  }

  // Radiance from a light that the last BSDF sample found, weighted against next-event estimation
  // of the same light.
  void add_found_light(int k, const LightHit& at) {
    const Light& light = scene_.lights()[static_cast<size_t>(k)];
    const Rgb Le = light.eval(at);
    if (Le.is_black()) return;
    double w = 1;
    if (!specular_)
      w = use_mis_ ? power_heuristic(prev_pdf_, light.pdf(at)) : (nee_area_ ? 0.0 : 1.0);
    add(k, beta_ * Shading::light(Le) * w);
  }
  // Light k's contribution c: to the path's radiance and, with light groups, to light k's share.
  void add(int k, const Color& c) {
    L_ += c;
    if (by_light_) (*by_light_)[static_cast<size_t>(k)] += c;
  }

  // Next-event estimation: one sample of every light, held with its shadow test; area lights and
  // the environment weighted against BSDF sampling (lights.h states what a sample holds).
  void sample_lights(const PathVertex& v) {
    const SurfaceHit& hit = v.hit;
    for (size_t k = 0; k < scene_.lights().size(); ++k) {
      const Light& light = scene_.lights()[k];
      const bool delta = light.is_delta();
      if (!delta && !nee_area_) continue;
      const std::optional<LightSample> ls = light.sample(hit.p, rng_);
      if (!ls) continue;
      const Vec3 wi = hit.shading.to_local(ls->wi);
      // Shadow terminator (Hanika 2021, render_scene.h SurfaceHit::lift_front): on a low-poly
      // mesh with vertex normals, the shading normal sees lights that the flat facet has behind
      // it, or that a neighbouring facet hides, and Veach's rule (consistent) then blackens whole
      // facets along the terminator. For reflection, the shadow ray starts instead on the smooth
      // surface the vertex normals describe, above the facet, and decides alone: light that the
      // facet really hides still meets it there, so nothing leaks through.
      const Vec3 lift = v.wo_ng >= 0 ? hit.lift_front : hit.lift_back;
      const bool lifted = !hit.on_fiber() && v.wo.z * wi.z > 0 && !(lift == Vec3{});
      const bool agrees = v.consistent(ls->wi, wi);
      if (!lifted && !agrees) continue;
      const Color f = Shading::f(v.bsdf, v.wo, wi);
      if (f.is_black()) continue;
      // BSDF sampling stops at directions the facet disagrees on, so there this is the only
      // strategy and takes the whole weight.
      const double w =
          delta || !use_mis_ || !agrees ? 1.0 : power_heuristic(ls->pdf, v.bsdf.pdf(v.wo, wi));
      ShadowTest<Color> t = shadow_test(v, lifted ? &lift : nullptr, *ls);
      t.light = static_cast<int>(k);
      t.contribution =
          beta_ * f * Shading::light(ls->L) * (std::abs(wi.z) * (w * ls->falloff) / ls->pdf);
      hold(std::move(t));
    }
  }
  // The shadow test of light sample 'ls' at v: from just off the surface on the light's side, or
  // from the lifted point off it on the viewer's side ('lift' non-null), to the light (at
  // infinity, or just short of the sample's point).
  ShadowTest<Color> shadow_test(const PathVertex& v, const Vec3* lift,
                                const LightSample& ls) const {
    const SurfaceHit& hit = v.hit;
    ShadowTest<Color> t;
    t.ignore_fiber = hit.fiber;
    const Vec3 o = lift ? hit.p + *lift + hit.ng * (v.wo_ng >= 0 ? hit.offset : -hit.offset)
                        : hit.spawn_origin(ls.at_infinity ? ls.wi : ls.p_light - hit.p);
    if (ls.at_infinity) {
      t.ray = {o, ls.wi, 1e300};
      return t;
    }
    const Vec3 to = ls.p_light - o;
    const double d = length(to);
    if (!(d > 0)) {
      t.decided = lift ? 1 : 0;  // a lifted point at the light counts as hidden
      return t;
    }
    t.ray = {o, to / d, d * (1 - 1e-5)};
    return t;
  }
  void hold(ShadowTest<Color>&& t) {
    if (t.decided < 0) {
      ++rays_.shadow;
      if (on_ray_) (*on_ray_)(t.ray, true);
    }
    if (n_held_ == kHeldShadows) answer_shadows(nullptr);
    std::construct_at(&held_.test[n_held_++], std::move(t));
  }

  // Continues the path by sampling the BSDF (and Russian roulette); false: the path ends.
  bool extend(const PathVertex& v, int depth) {
    const double u_lobe = rng_.uniform();
    const Vec2 u{rng_.uniform(), rng_.uniform()};
    const auto bs = v.bsdf.sample(v.wo, u, u_lobe);
    if (!bs || bs->weight.is_black() || !(bs->pdf > 0 || bs->is_delta)) return false;
    const Vec3 wi = normalize(v.hit.shading.to_world(bs->wi));
    if (!v.consistent(wi, bs->wi)) return false;
    const Color weight = Shading::weight(v.bsdf, v.wo, *bs);
    if (weight.is_black()) return false;
    beta_ *= weight;
    specular_ = bs->is_delta;
    prev_pdf_ = bs->pdf;
    ray_ = {v.hit.spawn_origin(wi), wi};
    ignore_fiber_ = v.hit.fiber;
    ++rays_.bounce;
    if (depth + 1 >= settings_.rr_depth) {
      const double q = std::min(0.95, beta_.max_component());
      if (!(rng_.uniform() < q)) return false;
      beta_ = beta_ / q;
    }
    return true;
  }

  const RenderScene& scene_;
  const RenderSettings& settings_;
  Rng& rng_;
  RayCounts& rays_;
  const RayObserver* on_ray_;
  const bool use_mis_ = settings_.sampling == LightSampling::mis;
  const bool nee_area_ = settings_.sampling != LightSampling::bsdf_only;
  Color L_ = Color(0.0), beta_ = Color(1.0);
  std::optional<std::array<Color, kMaxLightGroups>> by_light_;  // with light groups
  Ray ray_;
  bool specular_ = true;  // camera rays and delta bounces are not covered by next-event estimation
  double prev_pdf_ = 0;
  // Rays that leave a fiber pass through it (its own fiber never occludes a point of it).
  int64_t ignore_fiber_ = kNoFiber;
  // One record for every vertex: a hit overwrites all of it (RenderScene::intersect).
  SurfaceHit hit_;
  std::optional<PathVertex> vertex_;  // the last vertex, on hit_
  // The first n_held_ are constructed (hold): a path starts without filling all four, whose
  // stores showed in the render's profile.
  union Held {
    Held() {}
    ShadowTest<Color> test[kHeldShadows];
  } held_;
  int n_held_ = 0;
};

// Answers the held shadow rays of the live paths of a group: those that ignore no fiber in
// packets, the others one by one.
template <class Trace>
void answer_group_shadows(const RenderScene& scene, std::span<std::optional<Trace>> trace,
                          const bool* alive) {
  constexpr int kGroup = RenderScene::kPacketRays;
  int8_t blocked[kGroup][Trace::kHeldShadows];
  std::array<Ray, kGroup> packet;
  std::array<int8_t*, kGroup> answer;
  bool packet_blocked[kGroup];
  int m = 0;
  auto flush = [&] {
    scene.occluded_coherent({packet.data(), size_t(m)}, packet_blocked);
    for (int k = 0; k < m; ++k) *answer[k] = packet_blocked[k] ? 1 : 0;
    m = 0;
  };
  for (size_t j = 0; j < trace.size(); ++j) {
    if (!alive[j]) continue;
    const auto held = trace[j]->held();
    for (size_t i = 0; i < held.size(); ++i) {
      blocked[j][i] = -1;
      if (held[i].decided >= 0 || held[i].ignore_fiber != kNoFiber) continue;
      packet[m] = held[i].ray;
      answer[m++] = &blocked[j][i];
      if (m == kGroup) flush();
    }
  }
  if (m > 0) flush();
  for (size_t j = 0; j < trace.size(); ++j)
    if (alive[j]) trace[j]->answer_shadows(blocked[j]);
}

// The paths of up to RenderScene::kPacketRays camera rays of one pixel, each with its own stream
// *rng[j]: their first hits found together, and those of their first vertices' shadow rays that
// ignore no fiber answered together (RenderScene::intersect_coherent, occluded_coherent: the
// rays start near each other, and a parallel or distant light's run nearly parallel); the rest
// of each path as trace_path traces it. Each path does what trace_path does, in the same order,
// so the bits are the same. out[j]: the path's colour; first_mesh[j] the shape its
// camera ray meets (-1: none); when first_hits is not null, first_hits[j] is that hit, and
// found[j] whether there is one; with light groups, out_by_light[j * kMaxLightGroups + k] the
// path's colour from light k.
template <class Shading>
void trace_camera_group(const RenderScene& scene, std::span<const Ray> rays, Rng* const* rng,
                        const RenderSettings& s, RayCounts& counts, const RayObserver* on_ray,
                        Rgb* out, Rgb* out_by_light, int64_t* first_mesh, SurfaceHit* first_hits,
                        bool* found) {
  constexpr int kGroup = RenderScene::kPacketRays;
  using Trace = PathTrace<Shading>;
  const int n = static_cast<int>(rays.size());
  std::array<std::optional<Trace>, kGroup> trace;
  std::array<SurfaceHit*, kGroup> record;
  for (int j = 0; j < n; ++j) {
    trace[j].emplace(scene, s, *rng[j], counts, on_ray);
    record[j] = &trace[j]->record();
  }
  scene.intersect_coherent(rays, record.data(), found);
  bool alive[kGroup];
  bool any = false;
  for (int j = 0; j < n; ++j) {
    if (first_hits && found[j]) first_hits[j] = *record[j];
    alive[j] = trace[j]->start(rays[j], &first_mesh[j], {true, found[j]});
    any = any || alive[j];
  }
  // Deeper vertices are not taken in step: their rays are incoherent, and Embree's packets
  // answered them no faster (docs/PERFORMANCE.md).
  if (any) answer_group_shadows<Trace>(scene, {trace.data(), size_t(n)}, alive);
  for (int j = 0; j < n; ++j) {
    if (alive[j]) trace[j]->go_on();
    out[j] = trace[j]->result();
    if (s.light_groups) trace[j]->light_results(out_by_light + size_t(j) * kMaxLightGroups);
  }
}

}  // namespace

Rgb trace_path(const RenderScene& scene, const Ray& ray, const RenderSettings& settings, Rng& rng,
               RayCounts& rays, int64_t* first_mesh, const RayObserver* on_ray) {
  return settings.spectral
             ? PathTrace<BandShading>(scene, settings, rng, rays, on_ray).run(ray, first_mesh)
             : PathTrace<RgbShading>(scene, settings, rng, rays, on_ray).run(ray, first_mesh);
}

namespace {

void check_render_settings(const RenderSettings& s) {
  if (s.width < 1 || s.height < 1 || s.spp < 1 || s.tile_size < 1 || s.max_depth < 0 ||
      s.rr_depth < 0)
    throw Error("", "render", "width, height, spp and tile size must be positive");
  if (!(s.time_limit_s >= 0) || !std::isfinite(s.time_limit_s))
    throw Error("", "render.time_limit_s", "must be a finite number of seconds >= 0");
  if (s.light_groups && s.time_limit_s > 0)
    throw Error("", "render.light_groups", "not with a time limit");
}

// Per-pixel sums of radiance, albedo and normal, in sample order.
struct PixelSums {
  double L[3] = {0, 0, 0}, albedo[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
};

// The render of a window of the film, tile by tile in parallel, in passes of samples per pixel.
// Each sample has its own random stream (seed, pixel, sample index), so the image does not
// depend on the tiles, threads or passes.
class WindowRender {
 public:
  WindowRender(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
               const ProgressCallback& progress, const RenderObservers& observers,
               const PixelWindow& win)
      : scene_(scene),
        camera_(camera),
        s_(s),
        progress_(progress),
        observers_(observers),
        win_(win),
        ww_(win.width()),
        wh_(win.height()),
        npx_(size_t(ww_) * wh_),
        tx_((ww_ + s.tile_size - 1) / s.tile_size),
        ty_((wh_ + s.tile_size - 1) / s.tile_size),
        tiles_(uint64_t(tx_) * ty_),
        tile_rays_(tiles_),
        tile_nonfinite_(tiles_, 0),
        total_(uint64_t(npx_) * s.spp) {}

  // The film's images, zeroed in slices with a poll between them (zero_polled.h); false when
  // cancelled meanwhile.
  bool make_film() {
    const auto keep_going = [this] {
      report(0);
      return !cancel_.load();
    };
    if (s_.light_groups) out_.light_images.resize(scene_.lights().size());
    for (Image& im : out_.light_images)
      if (!film_image(im, keep_going)) return false;
    return film_image(out_.image, keep_going) &&
           (!s_.aov_albedo || film_image(out_.albedo, keep_going)) &&
           (!s_.aov_normal || film_image(out_.normal, keep_going));
  }

  // Every sample of every pixel in one pass.
  void render_all() {
    pass(0, s_.spp, nullptr);
    out_.spp_done = s_.spp;
  }
  // One sample per pixel a pass until the time limit, so that the image is always a whole
  // number of samples per pixel; the sums are kept between passes (72 bytes a pixel), per tile,
  // each made by its tile's first task: zeroing them all at once (a gigabyte at 4096 x 4096) took
  // seconds in which a cancel went unseen.
  void render_timed() {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::vector<PixelSums>> sums(tiles_);
    int n = 0;
    while (n < s_.spp && !cancel_.load()) {
      pass(n, n + 1, &sums);
      if (cancel_.load()) break;
      ++n;
      const double elapsed = seconds_since(start);
      if (elapsed >= s_.time_limit_s) break;
    }
    out_.spp_done = n;
    if (n > 0)
      for (uint64_t tile = 0; tile < tiles_; ++tile) {
        const TileBounds b = tile_bounds(tile);
        for (int y = b.y0; y < b.y1; ++y)
          for (int x = b.x0; x < b.x1; ++x)
            store(size_t(y) * ww_ + x, sums[tile][b.index(x, y)], 1.0 / n);
      }
  }
  RenderResult finish() {
    for (uint64_t t = 0; t < tiles_; ++t) {
      out_.rays += tile_rays_[t];
      out_.nonfinite_samples += tile_nonfinite_[t];
    }
    out_.cancelled = cancel_.load();
    return std::move(out_);
  }

 private:
  template <class KeepGoing>
  bool film_image(Image& im, KeepGoing& keep_going) const {
    im.width = ww_, im.height = wh_;
    im.x0 = win_.x0, im.y0 = win_.y0, im.film_width = s_.width, im.film_height = s_.height;
    return zero_polled(im.rgb, size_t(3) * npx_, keep_going);
  }

  // Samples [k0, k1) of every pixel of the window, tile by tile; 'sums' holds the running sums
  // when the render goes in several passes (null: one pass, stored as it ends). Progress (where
  // the front end sees Ctrl-C) is reported every kPollSamples samples of a thread, within a pixel
  // too, so that a cancel stops within milliseconds however large a tile's work; a pixel's samples
  // are added in the same order either way, so the bits do not depend on it.
  void pass(int k0, int k1, std::vector<std::vector<PixelSums>>* sums) {
    parallel_for(tiles_, s_.threads, [&](uint64_t tile) {
      if (cancel_.load(std::memory_order_relaxed)) return;
      const TileBounds b = tile_bounds(tile);
      const int x0 = b.x0, y0 = b.y0, x1 = b.x1, y1 = b.y1;
      std::vector<PixelSums>* tile_sums = sums ? &(*sums)[tile] : nullptr;
      if (tile_sums && tile_sums->empty()) tile_sums->resize(size_t(x1 - x0) * (y1 - y0));
      RayCounts rays;
      uint64_t unreported = 0;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const size_t i = size_t(y) * ww_ + x;
          PixelSums acc;
          PixelSums& into = tile_sums ? (*tile_sums)[b.index(x, y)] : acc;
          std::array<double, 3 * kMaxLightGroups> by_light{};  // light groups: no time limit
          for (int k = k0; k < k1; k += kPollSamples) {
            const int k_end = k1 - k > kPollSamples ? k + kPollSamples : k1;
            sample_pixel(win_.x0 + x, win_.y0 + y, k, k_end, into,
                         s_.light_groups ? by_light.data() : nullptr, rays, tile_nonfinite_[tile]);
            unreported += uint64_t(k_end - k);
            if (unreported >= kPollSamples) report(std::exchange(unreported, 0));
            // A cancelled render is discarded anyway: stop at once, not at the tile's end.
            if (cancel_.load(std::memory_order_relaxed)) return;
          }
          if (!sums) store(i, acc, 1.0 / s_.spp);
          for (size_t k = 0; k < out_.light_images.size(); ++k)
            for (size_t c = 0; c < 3; ++c)
              out_.light_images[k].rgb[3 * i + c] =
                  static_cast<float>(by_light[3 * k + c] / s_.spp);
        }
      }
      tile_rays_[tile] += rays;
      report(unreported);
    });
  }

  // The film pixels [x0, x1) x [y0, y1) of a tile (window coordinates), and a pixel's index in it.
  struct TileBounds {
    int x0, y0, x1, y1;
    size_t index(int x, int y) const { return size_t(y - y0) * (x1 - x0) + (x - x0); }
  };
  TileBounds tile_bounds(uint64_t tile) const {
    const int x0 = int(tile % tx_) * s_.tile_size, y0 = int(tile / tx_) * s_.tile_size;
    return {x0, y0, std::min(x0 + s_.tile_size, ww_), std::min(y0 + s_.tile_size, wh_)};
  }

  // 'samples' more done: tells the progress callback, which may ask to cancel.
  void report(uint64_t samples) {
    const uint64_t d = done_.fetch_add(samples) + samples;
    std::lock_guard lock(progress_mutex_);
    if (!cancel_.load() && !progress_({"render", d, total_, "samples"})) cancel_.store(true);
  }

  // Samples [k0, k1) of film pixel (x, y), added to 'acc' (and each light's share to
  // by_light[3 k + c] with light groups), in groups whose camera rays and first shadow rays are
  // traced together (trace_camera_group: the same bits as one by one).
  void sample_pixel(int x, int y, int k0, int k1, PixelSums& acc, double* by_light, RayCounts& rays,
                    uint64_t& nonfinite) const {
    constexpr int kGroup = RenderScene::kPacketRays;
    const uint64_t pixel = uint64_t(y) * s_.width + x;
    std::array<std::optional<Rng>, kGroup> rng;  // constructed per sample, not twice
    std::array<Rng*, kGroup> streams;
    std::array<Ray, kGroup> ray;
    std::array<Rgb, kGroup> L;
    std::optional<std::array<Rgb, kGroup * kMaxLightGroups>> L_by_light;  // with light groups
    if (by_light) L_by_light.emplace();
    Rgb* const out_by_light = by_light ? L_by_light->data() : nullptr;
    std::array<int64_t, kGroup> first;
    std::optional<std::array<SurfaceHit, kGroup>> hits;  // the camera rays' hits, for the AOVs
    if (aov_) hits.emplace();
    bool found[kGroup];
    for (int g = k0; g < k1; g += kGroup) {
      const int n = std::min(kGroup, k1 - g);
      for (int j = 0; j < n; ++j) {
        Rng& r = rng[j].emplace(s_.seed, pixel, uint64_t(g + j));
        streams[j] = &r;
        const double fx = (x + r.uniform()) / s_.width, fy = (y + r.uniform()) / s_.height;
        ray[j] = camera_.generate_ray(fx, fy, aspect_);
        ++rays.camera;
      }
      const std::span<const Ray> group(ray.data(), size_t(n));
      SurfaceHit* first_hits = hits ? hits->data() : nullptr;
      if (s_.spectral)
        trace_camera_group<BandShading>(scene_, group, streams.data(), s_, rays, on_ray_, L.data(),
                                        out_by_light, first.data(), first_hits, found);
      else
        trace_camera_group<RgbShading>(scene_, group, streams.data(), s_, rays, on_ray_, L.data(),
                                       out_by_light, first.data(), first_hits, found);
      for (int j = 0; j < n; ++j) {
        if (!finite(L[j])) {
          ++nonfinite;
          L[j] = Rgb(0.0);
        } else if (by_light) {
          for (size_t k = 0; k < scene_.lights().size(); ++k)
            for (int c = 0; c < 3; ++c)
              by_light[3 * k + c] += (*L_by_light)[size_t(j) * kMaxLightGroups + k][c];
        }
        acc.L[0] += L[j].r, acc.L[1] += L[j].g, acc.L[2] += L[j].b;
        if (observers_.on_sample) observers_.on_sample(pixel, first[j], L[j]);
        if (aov_) add_aovs(ray[j], found[j] ? &(*hits)[j] : nullptr, pixel, g + j, acc);
      }
    }
  }

  // The albedo and normal passes of sample k of a pixel, whose camera ray is 'ray' and meets
  // 'first' (null: nothing).
  void add_aovs(const Ray& ray, const SurfaceHit* first, uint64_t pixel, int k,
                PixelSums& acc) const {
    // Its own stream (the sample index with the top bit set, never a render sample), so
    // asking for passes leaves the image's bits alone.
    Rng aov_rng(s_.seed, pixel, uint64_t(k) | (uint64_t(1) << 63));
    if (!first) return;
    const SurfaceHit& hit = *first;
    const Vec3 wo_world = -ray.d;
    if (s_.aov_normal) {
      const Vec3 n = dot(hit.shading.n, wo_world) < 0 ? -hit.shading.n : hit.shading.n;
      acc.normal[0] += n.x, acc.normal[1] += n.y, acc.normal[2] += n.z;
    }
    if (s_.aov_albedo) {
      const Vec3 wo = hit.shading.to_local(wo_world);
      const double u_lobe = aov_rng.uniform();
      const Vec2 u{aov_rng.uniform(), aov_rng.uniform()};
      const BoundBsdf bsdf = scene_.bsdf_at(hit);
      const auto bs = bsdf.sample(wo, u, u_lobe);
      if (bs && finite(bs->weight)) {
        const Rgb a =
            s_.spectral ? BandShading::to_rgb(BandShading::weight(bsdf, wo, *bs)) : bs->weight;
        acc.albedo[0] += a.r, acc.albedo[1] += a.g, acc.albedo[2] += a.b;
      }
    }
  }

  void store(size_t i, const PixelSums& acc, double inv_n) {
    for (int c = 0; c < 3; ++c) {
      out_.image.rgb[3 * i + c] = static_cast<float>(acc.L[c] * inv_n);
      if (s_.aov_albedo) out_.albedo.rgb[3 * i + c] = static_cast<float>(acc.albedo[c] * inv_n);
      if (s_.aov_normal) out_.normal.rgb[3 * i + c] = static_cast<float>(acc.normal[c] * inv_n);
    }
  }

  const RenderScene& scene_;
  const Camera& camera_;
  const RenderSettings& s_;
  const ProgressCallback& progress_;
  const RenderObservers& observers_;
  const PixelWindow win_;
  const int ww_, wh_;
  const size_t npx_;
  const int tx_, ty_;
  const uint64_t tiles_;
  const bool aov_ = s_.aov_albedo || s_.aov_normal;
  const RayObserver* const on_ray_ = observers_.on_ray ? &observers_.on_ray : nullptr;
  const double aspect_ = double(s_.width) / s_.height;
  RenderResult out_;
  std::vector<RayCounts> tile_rays_;
  std::vector<uint64_t> tile_nonfinite_;
  const uint64_t total_;
  std::atomic<bool> cancel_{false};
  std::atomic<uint64_t> done_{0};
  static constexpr int kPollSamples = 4096;  // about 2 ms of one thread at 0.4 us a sample
  std::mutex progress_mutex_;
};

}  // namespace

double render_bytes(const RenderSettings& s, bool preview, bool mask) {
  const int images = 1 + (s.aov_albedo ? 1 : 0) + (s.aov_normal ? 1 : 0);
  const double per_pixel = images * 3 * sizeof(float) +
                           (s.time_limit_s > 0 ? sizeof(PixelSums) : 0) + (preview ? 3 : 0) +
                           (mask ? sizeof(uint32_t) + 6 * sizeof(double) + sizeof(float) : 0);
  const PixelWindow win = s.crop.value_or(PixelWindow{0, s.width, 0, s.height});
  return double(win.width()) * double(win.height()) * per_pixel;
}

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& s,
                    const ProgressCallback& progress, const RenderObservers& observers) {
  check_render_settings(s);
  if (s.light_groups && scene.lights().size() > size_t(kMaxLightGroups))
    throw Error("", "render.light_groups",
                "at most " + std::to_string(kMaxLightGroups) + " lights (the scene has " +
                    std::to_string(scene.lights().size()) + ")");
  const PixelWindow win = s.crop.value_or(PixelWindow{0, s.width, 0, s.height});
  check_crop(win, s.width, s.height, "", "render.crop");
  if (s.spectral) scene.check_spectral();
  // Woven meshes at the level their footprint calls for (weave_level.h); a scene without any is
  // rendered as it is, not copied.
  std::vector<WeaveLevelChoice> levels = choose_weave_levels(scene, camera, s);
  std::optional<RenderScene> leveled;
  if (!levels.empty()) leveled = scene.with_weave_levels(weave_flags(levels));
  WindowRender film(leveled ? *leveled : scene, camera, s, progress, observers, win);
  if (film.make_film()) {  // false: cancelled while the film was zeroed, as finish() reports
    if (s.time_limit_s == 0)
      film.render_all();
    else
      film.render_timed();
  }
  RenderResult out = film.finish();
  out.weave_levels = std::move(levels);
  return out;
}

}  // namespace weft
