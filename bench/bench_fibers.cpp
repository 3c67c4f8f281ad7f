// Fibers as round curves against triangle tubes (bench/include/weft/bench/fiber_bench.h), one
// benchmark per representation on the red-cotton patch at fiber detail. Counters: rays per second
// of RenderScene::intersect on rays leaving fibers (own fiber ignored) and of the path tracer,
// build seconds, and the one-fiber render's error against the Lambertian fiber's closed form
// (of the total scattered light and relative L2, and the renders' own noise).
#include <benchmark/benchmark.h>

#include <vector>

#include "weft/bench/fiber_bench.h"

namespace {

const std::vector<weft::FiberBenchRow>& rows() {
  static const std::vector<weft::FiberBenchRow> r = weft::bench_fibers(weft::FiberBenchOptions{});
  return r;
}

void BM_FiberGeometry(benchmark::State& state, size_t index) {
  const weft::FiberBenchRow& r = rows()[index];
  for (auto _ : state) benchmark::DoNotOptimize(r.rays_per_s);  // measured once, in rows()
  state.counters["rays_per_s"] = r.rays_per_s;
  state.counters["path_rays_per_s"] = r.path_rays_per_s;
  state.counters["build_s"] = r.build_s;
  state.counters["triangles"] = double(r.triangles);
  state.counters["segments"] = double(r.curve_segments);
  state.counters["one_fiber_total_err"] = r.one_fiber_total_error;
  state.counters["one_fiber_rms_err"] = r.one_fiber_rms_error;
  state.counters["one_fiber_noise"] = r.one_fiber_noise;
}

const bool registered = [] {
  const weft::FiberBenchOptions o;
  for (size_t i = 0; i < o.geometries.size(); ++i) {
    const auto& g = o.geometries[i];
    const std::string name = g.type == weft::FiberGeometry::Type::curves
                                 ? "BM_FiberGeometry/curves"
                                 : "BM_FiberGeometry/tubes:" + std::to_string(g.tube_sides);
    benchmark::RegisterBenchmark(name.c_str(), BM_FiberGeometry, i)->Iterations(1);
  }
  return true;
}();

}  // namespace
