// Mie solver and fiber medium timings. x spans the sizes a fiber medium meets (inclusions, x ~
// 1-100) up to the large spheres the solver must still handle; m = 1.5 + 0.001i (weakly absorbing).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "weft/fiber/medium.h"
#include "weft/fiber/mie.h"

static void BM_MieEfficiencies(benchmark::State& state) {
  const double x = static_cast<double>(state.range(0));
  for (auto _ : state) {
    const weft::MieResult r = weft::mie_sphere({1.5, 0.001}, x);
    benchmark::DoNotOptimize(r.qext);
  }
  state.counters["terms"] = weft::mie_term_count(x);
}
BENCHMARK(BM_MieEfficiencies)
    ->Arg(10)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMicrosecond);

// The cotton air-void index (1.0 / 1.557) with amplitudes at 1000 angles.
static void BM_MieAmplitudes1000Angles(benchmark::State& state) {
  const double x = static_cast<double>(state.range(0));
  std::vector<double> mu(1000);
  for (size_t i = 0; i < mu.size(); ++i) mu[i] = std::cos(M_PI * i / (mu.size() - 1));
  for (auto _ : state) {
    const weft::MieResult r = weft::mie_sphere({1.0 / 1.557, 0.0}, x, mu);
    benchmark::DoNotOptimize(r.s1.data());
  }
}
BENCHMARK(BM_MieAmplitudes1000Angles)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond);

// A whole preset medium (33 bands, lognormal species, phase tables) on one thread.
static void BM_FiberMediumRedCotton(benchmark::State& state) {
  const weft::FiberSpec spec = weft::load_fiber_spec("red-cotton");
  weft::MediumOptions o;
  o.threads = 1;
  for (auto _ : state) {
    const weft::FiberMedium m = weft::build_fiber_medium(spec, {}, o);
    benchmark::DoNotOptimize(m.bands.data());
  }
}
BENCHMARK(BM_FiberMediumRedCotton)->Unit(benchmark::kMillisecond);
