#include <benchmark/benchmark.h>

#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"

static void BM_EqualAreaSquareToSphere(benchmark::State& state) {
  weft::Rng rng(1);
  for (auto _ : state) {
    const weft::Vec3 d = weft::equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    benchmark::DoNotOptimize(d);
  }
}
BENCHMARK(BM_EqualAreaSquareToSphere);
