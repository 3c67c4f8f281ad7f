// Render throughput on a generated woven patch (~65k triangles): raw Embree rtcIntersect1 against
// the path tracer (rays per second as counters), single-threaded so the two compare directly.
// `weft bench render` runs the same comparison with thread scaling and a ~1M-triangle patch.
#include <benchmark/benchmark.h>

#include <memory>

#include "weft/bench/render_bench.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/render_scene.h"

namespace {

struct Fixture {
  weft::SceneDescription desc;
  std::unique_ptr<weft::RenderScene> scene;
  Fixture() {
    weft::WeaveParams p;  // 2 x 16 yarns x 128 segments x 8 sides x 2 = 65,536 triangles
    p.yarns = 16, p.segments = 128, p.sides = 8;
    desc = weft::weave_bench_scene(p);
    scene = std::make_unique<weft::RenderScene>(desc);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void BM_EmbreeIntersectRandomRays(benchmark::State& state) {
  const auto& f = fixture();
  const weft::Bounds3 b = f.scene->bounds();
  weft::Rng rng(1);
  uint64_t rays = 0;
  for (auto _ : state) {
    // Rays from random points in the patch's box in uniform directions: incoherent like bounces.
    const weft::Vec3 o{b.lo.x + (b.hi.x - b.lo.x) * rng.uniform(),
                       b.lo.y + (b.hi.y - b.lo.y) * rng.uniform(),
                       b.lo.z + (b.hi.z - b.lo.z) * rng.uniform()};
    const double z = 1 - 2 * rng.uniform(), phi = 2 * weft::kPi * rng.uniform(),
                 r = std::sqrt(1 - z * z);
    const weft::Ray ray{o, {r * std::cos(phi), r * std::sin(phi), z}};
    benchmark::DoNotOptimize(weft::embree_hit_distance(*f.scene, weft::to_embree(ray, false)));
    ++rays;
  }
  state.counters["rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EmbreeIntersectRandomRays);

void BM_PathTraceWovenPatch(benchmark::State& state) {
  const auto& f = fixture();
  weft::RenderSettings s;
  s.width = s.height = 64;
  s.spp = 2;
  s.threads = 1;
  uint64_t rays = 0;
  for (auto _ : state) {
    const weft::RenderResult r = weft::render(*f.scene, *f.desc.camera, s);
    rays += r.rays.total();
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  state.counters["rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PathTraceWovenPatch)->Unit(benchmark::kMillisecond);

}  // namespace
