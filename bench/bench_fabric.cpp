// Fabric tables by summation (fabric/fabric_summation.h): the paper's summation, the
// baseline, and the visible-layer summation on the orientations the bundled red-cotton sample
// shows at fiber detail (as `weft bake fabric --method summation-visible --detail fiber` uses
// them), R = 4, 8 direction pairs per cell pair, one thread. The fiber table is a smooth RGB
// function tabulated at R = 8 (the cost of a lookup does not depend on its values).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "weft/core/math.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/scenes/weave.h"

namespace {

using namespace weft;

const TabulatedBsdfTable& fiber() {
  static const TabulatedBsdfTable t = [] {
    auto f = TabulatedBsdfTable::from_function(
        8, 3,
        [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          const double s = (wo.z > 0 ? 0.3 : 0.1) * (1 + 0.5 * wo.x * wi.x) * kInvPi;
          v[0] = s, v[1] = 0.3 * s, v[2] = 0.2 * s;
        },
        1, 1, 1);
    f.kind = "fiber";
    return f;
  }();
  return t;
}

std::vector<FiberOrientation> orientations(bool from_above) {
  static const WovenSample sample = [] {
    WeaveOptions o;
    o.detail = "fiber";
    return make_woven_sample(overlay(red_cotton_weave_options(), o));
  }();
  std::vector<FiberOrientation> out;
  for (const Vec3& t : visible_fiber_tangents(sample, from_above)) out.push_back({t, 1.0});
  return out;
}

void BM_FabricSummation(benchmark::State& state) {
  FabricSummationOptions o;
  o.method = state.range(0) ? FabricSummation::kVisible : FabricSummation::kPaper;
  o.resolution = 4;
  o.threads = 1;
  if (o.method == FabricSummation::kVisible) {
    o.top = orientations(true);
    o.bottom = orientations(false);
  }
  for (auto _ : state) benchmark::DoNotOptimize(sum_fabric_table(fiber(), o).values.data());
}

}  // namespace

BENCHMARK(BM_FabricSummation)->ArgName("visible")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
