// Photon transport in a cotton-like fiber (radius 10 um, mu_s 0.05/um, mu_a 0.005/um, HG g 0.8,
// n 1.557 in air): scattering events per second on one core for a bare walk and for a walk that
// bins every exit on the BSSRDF's grid (BssrdfGrid::cell_of, same run, so their ratio is
// meaningful), and the 1 -> 2 thread speed-up of a fixed-size batch.
#include <benchmark/benchmark.h>

#include "weft/fiber/bssrdf.h"
#include "weft/fiber/transport_cylinder.h"

namespace {

using namespace weft;

TransportMedium cotton_medium() {
  TransportMedium m;
  m.mu_a = 0.005;
  m.mu_s = 0.05;
  m.n = 1.557;
  m.phase = PhaseFunction::henyey_greenstein(0.8);
  return m;
}

constexpr double kRadiusUm = 10;
constexpr int kPhotonsPerIteration = 4096;
const Vec3 kBeam = normalize(Vec3{0.3, 0.1, -1});  // travel direction of the light

BssrdfGrid table_grid() {
  BssrdfGrid g;
  g.u_bins = 64;
  g.v_bins = 65;
  g.v_range = 20 * kRadiusUm;
  g.direction_resolution = 8;
  g.surface_in_table = false;
  g.keep_squares = true;
  return g;
}

// Bins every exit into a dense (u, v, direction) table with sums of squares, as simulate_bssrdf
// does for a single incident direction.
struct TableRecorder {
  BssrdfGrid grid = table_grid();
  std::vector<double> sum = std::vector<double>(grid.cells()),
                      sum2 = std::vector<double>(grid.cells());
  double overflow = 0;
  void on_exit(const ExitEvent& e) {
    const int64_t k = grid.cell_of(e);
    if (k < 0) {
      overflow += e.weight;
      return;
    }
    sum[k] += e.weight;
    sum2[k] += e.weight * e.weight;
  }
};

template <class Recorder>
void walk_fiber(benchmark::State& state, Recorder& recorder) {
  const CylinderTransport fiber(CylinderGeometry(kRadiusUm, 1.0), cotton_medium());
  uint64_t iteration = 0, scatterings = 0, photons = 0;
  for (auto _ : state) {
    Rng rng(1, iteration++);
    PhotonTally tally;
    for (int i = 0; i < kPhotonsPerIteration; ++i) {
      const Vec3 p = cylinder_beam_entry(fiber.geometry(), kBeam, rng.uniform());
      fiber.launch_external(CylinderGeometry::kSurface, p, kBeam, 1.0, rng, recorder, tally);
    }
    scatterings += tally.scatterings;
    photons += tally.photons;
    benchmark::DoNotOptimize(tally);
  }
  state.counters["scatterings_per_s"] =
      benchmark::Counter(static_cast<double>(scatterings), benchmark::Counter::kIsRate);
  state.counters["photons_per_s"] =
      benchmark::Counter(static_cast<double>(photons), benchmark::Counter::kIsRate);
  state.counters["scatterings_per_photon"] =
      static_cast<double>(scatterings) / static_cast<double>(photons);
}

void BM_FiberWalkBare(benchmark::State& state) {
  NullRecorder none;
  walk_fiber(state, none);
}
BENCHMARK(BM_FiberWalkBare)->Unit(benchmark::kMillisecond);

void BM_FiberWalkRecording(benchmark::State& state) {
  TableRecorder table;
  walk_fiber(state, table);
  benchmark::DoNotOptimize(table.overflow);
}
BENCHMARK(BM_FiberWalkRecording)->Unit(benchmark::kMillisecond);

// Fixed-size work (2^18 photons) at 1 and 2 threads: speed-up = time(1) / time(2).
void BM_FiberBeamBatch(benchmark::State& state) {
  CylinderBeamSetup s;
  s.medium = cotton_medium();
  s.radius = kRadiusUm;
  s.direction = kBeam;
  TaskBatch b;
  b.items = 1u << 18;
  b.seed = 1;
  b.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(simulate_cylinder_beam(s, b));
}
BENCHMARK(BM_FiberBeamBatch)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// The same for a whole BSSRDF table (2^20 photons; exits merged into the table in task order).
void BM_FiberBssrdfBatch(benchmark::State& state) {
  const FiberBandPhysics fiber = smooth_fiber_physics(cotton_medium(), kRadiusUm, 1.0);
  const BssrdfIncidence incidence = BssrdfIncidence::from(normalize(Vec3{0.3, 0.1, 1}));
  TaskBatch b;
  b.items = 1u << 20;
  b.items_per_task = 16384;
  b.seed = 1;
  b.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(simulate_bssrdf(fiber, table_grid(), incidence, b));
}
BENCHMARK(BM_FiberBssrdfBatch)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
