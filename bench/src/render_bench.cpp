#include "weft/bench/render_bench.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "weft/core/clock.h"
#include "weft/core/distribution.h"
#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdfs.h"
#include "weft/scenes/embree_context.h"
#include "weft/scenes/render_scene.h"

namespace weft {
namespace {

// Diffuse rays as a path tracer's bounces from opaque surfaces see them: from area-uniform surface
// points, cosine distributed about the geometric normal on the side the vertex normals face (a
// random side where the mesh has no normals).
std::vector<Ray> diffuse_rays(const SceneDescription& desc, size_t n, uint64_t seed) {
  std::vector<std::pair<size_t, uint32_t>> tris;
  std::vector<double> areas;
  for (size_t m = 0; m < desc.meshes.size(); ++m) {
    const auto& mesh = *desc.meshes[m];
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Vec3 p0 = mesh.position(mesh.indices[3 * t]);
      tris.push_back({m, t});
      areas.push_back(length(cross(mesh.position(mesh.indices[3 * t + 1]) - p0,
                                   mesh.position(mesh.indices[3 * t + 2]) - p0)));
    }
  }
  const Distribution1D pick(areas);
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    Rng rng(seed, i);
    const auto [m, t] = tris[pick.sample_discrete(rng.uniform())];
    const auto& mesh = *desc.meshes[m];
    const Vec3 p0 = mesh.position(mesh.indices[3 * t]), p1 = mesh.position(mesh.indices[3 * t + 1]),
               p2 = mesh.position(mesh.indices[3 * t + 2]);
    const double su = std::sqrt(rng.uniform()), b1 = 1 - su, b2 = rng.uniform() * su;
    const Vec3 p = (1 - b1 - b2) * p0 + b1 * p1 + b2 * p2;
    Vec3 ng = normalize(cross(p1 - p0, p2 - p0));
    const double side = rng.uniform();
    if (!mesh.normals.empty()) {
      const uint32_t i0 = mesh.indices[3 * t];
      if (dot(ng, Vec3{mesh.normals[3 * i0], mesh.normals[3 * i0 + 1], mesh.normals[3 * i0 + 2]}) <
          0)
        ng = -ng;
    } else if (side < 0.5) {
      ng = -ng;
    }
    const Vec3 d =
        Frame::from_normal(ng).to_world(sample_cosine_hemisphere({rng.uniform(), rng.uniform()}));
    double mag = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    rays[i] = {p + ng * (1e-5 * mag + 1e-30), normalize(d)};
  }
  return rays;
}

// Queries per second of 'threads' threads answering query(i) for i in [0, n), in chunks of 4096.
// The answers (0 or 1 each) are summed so the work stays observable; 0 if that sum is impossible.
template <class Query>
double query_rate(size_t n, int threads, Query query) {
  const uint64_t chunk = 4096, chunks = (n + chunk - 1) / chunk;
  std::vector<uint64_t> hits(chunks, 0);
  const auto t0 = SteadyClock::now();
  parallel_for(chunks, threads, [&](uint64_t c) {
    uint64_t h = 0;
    const size_t end = std::min<size_t>(n, (c + 1) * chunk);
    for (size_t i = c * chunk; i < end; ++i) h += query(i);
    hits[c] = h;
  });
  const double s = seconds_since(t0);
  uint64_t total = 0;
  for (auto h : hits) total += h;
  return total <= n ? n / s : 0;
}

double embree_rate(const RenderScene& scene, const std::vector<Ray>& rays, int threads) {
  return query_rate(rays.size(), threads, [&](size_t i) {
    return std::isfinite(embree_hit_distance(scene, to_embree(rays[i], false)));
  });
}

double replay_rate(const RenderScene& scene, const std::vector<EmbreeRay>& log, int threads) {
  return query_rate(log.size(), threads, [&](size_t i) {
    const EmbreeRay& r = log[i];
    return r.shadow ? embree_occluded(scene, r) : std::isfinite(embree_hit_distance(scene, r));
  });
}

// Seconds for a fixed amount of floating-point work split into tasks, on 'threads' threads.
double arithmetic_seconds(int threads) {
  std::vector<double> out(64);
  const auto t0 = SteadyClock::now();
  parallel_for(64, threads, [&](uint64_t task) {
    Rng rng(1, task);
    double x = rng.uniform();
    for (int i = 0; i < 2000000; ++i) x = x * 0.999999 + 1e-7;
    out[task] = x;
  });
  const double s = seconds_since(t0);
  double sum = 0;
  for (double v : out) sum += v;
  return sum > 0 ? s : 0;
}

// The median of a non-empty list (the mean of the middle two for an even count).
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct PathRate {
  double all = 0, intersect = 0;
};
PathRate path_rate(const RenderScene& scene, const Camera& cam, const RenderBenchOptions& o,
                   int threads) {
  RenderSettings s = o.render;
  s.threads = threads;
  const auto t0 = SteadyClock::now();
  const RenderResult r = render(scene, cam, s);
  const double sec = seconds_since(t0);
  return {r.rays.total() / sec, (r.rays.camera + r.rays.bounce) / sec};
}

}  // namespace

EmbreeRay to_embree(const Ray& ray, bool shadow) {
  return {{static_cast<float>(ray.o.x), static_cast<float>(ray.o.y), static_cast<float>(ray.o.z)},
          {static_cast<float>(ray.d.x), static_cast<float>(ray.d.y), static_cast<float>(ray.d.z)},
          ray.tmax > 3e38 ? INFINITY : static_cast<float>(ray.tmax),
          shadow};
}

namespace {
// The ray of either bare query: r from tnear 0 to its tmax, seen by every geometry.
RTCRay rtc_ray(const EmbreeRay& r) {
  RTCRay ray;
  ray.org_x = r.org[0], ray.org_y = r.org[1], ray.org_z = r.org[2];
  ray.dir_x = r.dir[0], ray.dir_y = r.dir[1], ray.dir_z = r.dir[2];
  ray.tnear = 0.0f;
  ray.tfar = r.tmax;
  ray.mask = 0xFFFFFFFFu;
  ray.time = 0.0f;
  ray.flags = 0;
  return ray;
}
}  // namespace

double embree_hit_distance(const RenderScene& scene, const EmbreeRay& r) {
  RTCRayHit rh;
  rh.ray = rtc_ray(r);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  FiberQueryContext ctx;  // the fibers' filter functions read it
  rtcIntersect1(scene.embree_scene(), &ctx.embree, &rh);
  return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar;
}

bool embree_occluded(const RenderScene& scene, const EmbreeRay& r) {
  RTCRay ray = rtc_ray(r);
  FiberQueryContext ctx;
  rtcOccluded1(scene.embree_scene(), &ctx.embree, &ray);
  return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

void add_bench_materials_and_sun(SceneDescription& d) {
  MaterialBinding warp, weft;
  warp.type = weft.type = "lambert";
  warp.params = {{"reflectance", {0.6, 0.15, 0.1}}};
  weft.params = {{"reflectance", 0.5}};
  warp.field = "materials.warp";
  weft.field = "materials.weft";
  d.materials["warp"] = warp;
  d.materials["weft"] = weft;
  d.lights.directional.push_back({d.frame.direction(deg_to_rad(30), 0), Rgb(1.0)});
}

SceneDescription weave_bench_scene(const WeaveParams& params) {
  SceneDescription d;
  d.source = "weave bench scene";
  for (auto& m : make_weave(params))
    d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(m)));
  add_bench_materials_and_sun(d);
  d.camera = frame_box_orthographic(d.object_bounds(""), d.frame.direction(deg_to_rad(20), kPi),
                                    d.frame.normal);
  return d;
}

RenderBenchResult bench_render_scene(const SceneDescription& desc, const std::string& name,
                                     const RenderBenchOptions& o) {
  if (o.repeats < 1 || o.repeats > kMaxBenchRepeats)
    throw Error(
        "", "repeats",
        "must be 1 to " + std::to_string(kMaxBenchRepeats) + ", not " + std::to_string(o.repeats));
  RenderBenchResult r;
  r.name = name;
  auto t0 = SteadyClock::now();
  const RenderScene scene(desc);
  r.build_s = seconds_since(t0);
  r.triangles = scene.triangle_count();
  const auto rays = diffuse_rays(desc, o.diffuse_rays, o.render.seed);
  const Camera cam = desc.camera ? *desc.camera
                                 : frame_box_orthographic(scene.bounds(),
                                                          desc.frame.direction(deg_to_rad(20), kPi),
                                                          desc.frame.normal);
  std::vector<EmbreeRay> log;
  {
    RenderSettings s = o.render;
    s.threads = 1;  // the log then needs no lock and holds the rays in the tracer's tile order
    RenderObservers observers;
    observers.on_ray = [&](const Ray& ray, bool shadow) { log.push_back(to_embree(ray, shadow)); };
    render(scene, cam, s, no_progress(), observers);
  }
  // Repeats of every measurement, the tracer's run right after its rays' replay so that both see
  // the same machine: the ratio is taken within each repeat and the median and range reported, the
  // rates as their medians (the machines are shared; a run's neighbour may slow either side).
  // Each repeat also renders with a pixel's coherent rays answered one by one ('single'): what
  // the packets buy on this machine.
  const RenderScene single = scene.with_ray_packets(false);
  std::vector<double> replay, embree, one, many, many_intersect, machine, ratio;
  std::vector<double> single_rate, single_ratio, packet_gain;
  for (int rep = 0; rep < o.repeats; ++rep) {
    machine.push_back(arithmetic_seconds(1) / arithmetic_seconds(o.threads));
    embree.push_back(embree_rate(scene, rays, o.threads));
    one.push_back(path_rate(scene, cam, o, 1).all);
    replay.push_back(replay_rate(scene, log, o.threads));
    const PathRate m = path_rate(scene, cam, o, o.threads);
    many.push_back(m.all);
    many_intersect.push_back(m.intersect);
    ratio.push_back(m.all / replay.back());
    single_rate.push_back(path_rate(single, cam, o, o.threads).all);
    single_ratio.push_back(single_rate.back() / replay.back());
    packet_gain.push_back(m.all / single_rate.back());
  }
  r.repeats = o.repeats;
  r.machine_speedup = median(machine);
  r.embree_rays_per_s = median(embree);
  r.embree_replay_rays_per_s = median(replay);
  r.path_rays_per_s_1thread = median(one);
  r.path_rays_per_s = median(many);
  r.path_intersect_rays_per_s = median(many_intersect);
  r.ratio = r.path_rays_per_s / r.embree_rays_per_s;
  r.ratio_replay = median(ratio);
  r.ratio_replay_min = *std::min_element(ratio.begin(), ratio.end());
  r.ratio_replay_max = *std::max_element(ratio.begin(), ratio.end());
  r.ray_packets = scene.ray_packets();
  r.path_rays_per_s_one_by_one = median(single_rate);
  r.ratio_replay_one_by_one = median(single_ratio);
  r.packet_gain = median(packet_gain);
  r.speedup = r.path_rays_per_s / r.path_rays_per_s_1thread;
  return r;
}

}  // namespace weft
