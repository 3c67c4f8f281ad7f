// Materials: tabulated BSDF eval/sample at R = 16 and 32 (RGB), Cook-Torrance eval/sample, and
// the Lambert baseline to quote ratios against.
#include <benchmark/benchmark.h>

#include <map>
#include <vector>

#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"
#include "weft/materials/bsdfs.h"

namespace {

using namespace weft;

// Pre-drawn direction pairs (same-side for reflectors), so the loop times only the material.
struct Pairs {
  std::vector<Vec3> wo, wi;
  std::vector<Vec2> u;
  explicit Pairs(size_t n = 4096) {
    Rng rng(7);
    for (size_t i = 0; i < n; ++i) {
      Vec3 a = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
      Vec3 b = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
      if (a.z * b.z < 0) b.z = -b.z;
      wo.push_back(a), wi.push_back(b), u.push_back({rng.uniform(), rng.uniform()});
    }
  }
};
const Pairs& pairs() {
  static const Pairs p;
  return p;
}

const Bsdf& table_bsdf(int resolution) {
  static std::map<int, Bsdf> cache;
  auto it = cache.find(resolution);
  if (it == cache.end()) {
    const auto fiber = ClassicFiberBsdf::create(Rgb(0.7, 0.2, 0.1), {MicrofacetModel::kGgx, 0.3});
    const auto t = TabulatedBsdfTable::from_function(
        resolution, 3,
        [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          const Rgb f = fiber.eval(wo, wi);
          v[0] = f.r, v[1] = f.g, v[2] = f.b;
        },
        1, 1);
    it = cache.emplace(resolution, TabulatedBsdf{TabulatedBsdfData::prepare(t), Rgb(1.0)}).first;
  }
  return it->second;
}

void run_eval(benchmark::State& state, const Bsdf& b) {
  const Pairs& p = pairs();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.eval(p.wo[i], p.wi[i]));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
void run_sample(benchmark::State& state, const Bsdf& b) {
  const Pairs& p = pairs();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.sample(p.wo[i], p.u[i], 0.5));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_LambertEval(benchmark::State& s) {
  run_eval(s, LambertBsdf{Rgb(0.5)});
}
void BM_LambertSample(benchmark::State& s) {
  run_sample(s, LambertBsdf{Rgb(0.5)});
}
void BM_CookTorranceEval(benchmark::State& s) {
  const auto model = s.range(0) ? MicrofacetModel::kGgx : MicrofacetModel::kBeckmann;
  run_eval(s, CookTorranceBsdf{{model, 0.3}, kCottonIor, Rgb(1.0)});
}
void BM_CookTorranceSample(benchmark::State& s) {
  const auto model = s.range(0) ? MicrofacetModel::kGgx : MicrofacetModel::kBeckmann;
  run_sample(s, CookTorranceBsdf{{model, 0.3}, kCottonIor, Rgb(1.0)});
}
void BM_ClassicFiberCreate(benchmark::State& s) {
  for (auto _ : s)
    benchmark::DoNotOptimize(ClassicFiberBsdf::create(Rgb(0.5), {MicrofacetModel::kBeckmann, 0.3}));
}
void BM_TableEval(benchmark::State& s) {
  run_eval(s, table_bsdf(static_cast<int>(s.range(0))));
}
void BM_TableSample(benchmark::State& s) {
  run_sample(s, table_bsdf(static_cast<int>(s.range(0))));
}
void BM_MeasuredNbrdfEval(benchmark::State& s) {
  static const Bsdf b = MeasuredNbrdfBsdf{std::make_shared<const NbrdfNetwork>(
      NbrdfNetwork::load(find_measured_nbrdf("merl-red-fabric")))};
  run_eval(s, b);
}

}  // namespace

BENCHMARK(BM_LambertEval);
BENCHMARK(BM_LambertSample);
BENCHMARK(BM_CookTorranceEval)->ArgName("ggx")->Arg(0)->Arg(1);
BENCHMARK(BM_CookTorranceSample)->ArgName("ggx")->Arg(0)->Arg(1);
BENCHMARK(BM_ClassicFiberCreate)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TableEval)->ArgName("R")->Arg(16)->Arg(32);
BENCHMARK(BM_TableSample)->ArgName("R")->Arg(16)->Arg(32);
BENCHMARK(BM_MeasuredNbrdfEval);
