// Render throughput on a generated woven patch (~65k triangles): raw Embree rtcIntersect1 against
// the path tracer (rays per second as counters), single-threaded so the two compare directly.
// `weft bench render` runs the same comparison with thread scaling and a ~1M-triangle patch. And a
// spectral render's cost against an RGB one of the same spectral table.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <span>

#include "weft/bench/render_bench.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdf_table.h"
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

// The same patch with both yarns bound to a spectral fiber-like table (33 bands: red reflection
// and a diffuse transmission that carries red, so light scatters through the cloth), rendered in
// RGB (the table reduced at load) and as a spectral render (every band on every path), with the
// table read bilinearly and by cell: the spectral render's cost against the RGB baseline of the
// same run. Args: spectral (0/1), cell reads (0/1).
const weft::SceneDescription& spectral_table_patch(bool cell) {
  static const auto make = [](bool by_cell) {
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / "weft-bench-spectral-table.exr";
    static const bool written = [&] {
      weft::TabulatedBsdfTable::from_function(
          8, weft::kNumBands,
          [](const weft::Vec3& wo, const weft::Vec3& wi, std::span<double> v) {
            for (int b = 0; b < weft::kNumBands; ++b) {
              const double red = b >= 20 ? 0.7 : 0.1;
              v[b] = (wo.z * wi.z > 0 ? red * (0.5 + wi.z * wi.z) : 0.4 * red) * weft::kInvPi;
            }
          },
          1, 1)
          .write_exr(file);
      return true;
    }();
    (void)written;
    weft::SceneDescription d = fixture().desc;
    for (const char* key : {"warp", "weft"}) {
      d.materials[key].type = "fiber_table";
      d.materials[key].params = {{"file", file.string()},
                                 {"interpolation", by_cell ? "cell" : "bilinear"}};
    }
    return d;
  };
  static const weft::SceneDescription bilinear = make(false), by_cell = make(true);
  return cell ? by_cell : bilinear;
}

void BM_PathTraceSpectralTablePatch(benchmark::State& state) {
  const weft::SceneDescription& d = spectral_table_patch(state.range(1) != 0);
  const weft::RenderScene scene(d);
  weft::RenderSettings s;
  s.width = s.height = 64;
  s.spp = 2;
  s.threads = 1;
  s.spectral = state.range(0) != 0;
  uint64_t samples = 0;
  for (auto _ : state) {
    const weft::RenderResult r = weft::render(scene, *d.camera, s);
    samples += uint64_t(s.width) * s.height * s.spp;
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  state.counters["samples_per_s"] =
      benchmark::Counter(double(samples), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PathTraceSpectralTablePatch)
    ->ArgNames({"spectral", "cell"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace
