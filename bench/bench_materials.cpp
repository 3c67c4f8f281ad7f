// Materials: tabulated BSDF eval/sample at R = 8, 16 and 32 (RGB), bare and on a backing
// (fabric_table's backing_reflectance), the tables' preparation (sampling distributions),
// Cook-Torrance eval/sample, and the Lambert baseline to quote ratios against.
#include <benchmark/benchmark.h>

#include <map>
#include <vector>

#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"
#include "weft/materials/bsdfs.h"

namespace {

using namespace weft;

// Pre-drawn direction pairs (same-side for reflectors), so the loop times only the material.
struct Pairs {
  std::vector<Vec3> wo, wi;
  std::vector<Vec2> u;
  explicit Pairs(bool upper = false, size_t n = 4096) {
    Rng rng(7);
    for (size_t i = 0; i < n; ++i) {
      Vec3 a = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
      Vec3 b = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
      if (upper && a.z < 0) a.z = -a.z;  // a backed cloth is seen from above only
      if (a.z * b.z < 0) b.z = -b.z;
      wo.push_back(a), wi.push_back(b), u.push_back({rng.uniform(), rng.uniform()});
    }
  }
};
const Pairs& pairs(bool upper = false) {
  static const Pairs p(false), q(true);
  return upper ? q : p;
}

// A fiber-like table: classic-fiber reflection and a diffuse transmission of 0.6 (the summed
// fabric tables transmit 0.6-0.8 of red).
const TabulatedBsdfTable& test_table(int resolution) {
  static std::map<int, TabulatedBsdfTable> cache;
  auto it = cache.find(resolution);
  if (it == cache.end()) {
    const auto fiber = ClassicFiberBsdf::create(Rgb(0.7, 0.2, 0.1), {MicrofacetModel::kGgx, 0.3});
    auto t = TabulatedBsdfTable::from_function(
        resolution, 3,
        [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          const Rgb f = wo.z * wi.z > 0 ? fiber.eval(wo, wi) : Rgb(0.6 * kInvPi);
          v[0] = f.r, v[1] = f.g, v[2] = f.b;
        },
        1, 1);
    t.kind = "fabric";
    it = cache.emplace(resolution, std::move(t)).first;
  }
  return it->second;
}

const Bsdf& table_bsdf(int resolution, bool backed = false) {
  static std::map<std::pair<int, bool>, Bsdf> cache;
  auto it = cache.find({resolution, backed});
  if (it == cache.end()) {
    TabulatedBsdf b{TabulatedBsdfData::prepare(test_table(resolution)), Rgb(1.0)};
    if (backed) b.backing = TableBacking::make(*b.data, b.scale, Rgb(0.6));
    it = cache.emplace(std::pair{resolution, backed}, b).first;
  }
  return it->second;
}

void run_eval(benchmark::State& state, const Bsdf& b, bool upper = false) {
  const Pairs& p = pairs(upper);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.eval(p.wo[i], p.wi[i]));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
void run_sample(benchmark::State& state, const Bsdf& b, bool upper = false) {
  const Pairs& p = pairs(upper);
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
// The bare table seen from above, as the backed one is (same pairs).
void BM_TableSampleAbove(benchmark::State& s) {
  run_sample(s, table_bsdf(static_cast<int>(s.range(0))), true);
}
void BM_BackedTableEval(benchmark::State& s) {
  run_eval(s, table_bsdf(static_cast<int>(s.range(0)), true), true);
}
void BM_BackedTableSample(benchmark::State& s) {
  run_sample(s, table_bsdf(static_cast<int>(s.range(0)), true), true);
}
void BM_TablePrepare(benchmark::State& s) {
  const TabulatedBsdfTable& t = test_table(static_cast<int>(s.range(0)));
  for (auto _ : s) benchmark::DoNotOptimize(TabulatedBsdfData::prepare(t));
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
BENCHMARK(BM_TableEval)->ArgName("R")->Arg(8)->Arg(16)->Arg(32);
BENCHMARK(BM_TableSample)->ArgName("R")->Arg(8)->Arg(16)->Arg(32);
BENCHMARK(BM_TableSampleAbove)->ArgName("R")->Arg(8)->Arg(16);
BENCHMARK(BM_BackedTableEval)->ArgName("R")->Arg(8)->Arg(16);
BENCHMARK(BM_BackedTableSample)->ArgName("R")->Arg(8)->Arg(16);
BENCHMARK(BM_TablePrepare)->ArgName("R")->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeasuredNbrdfEval);
