#include "weft/fabric/straight_through.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "weft/core/rng.h"
#include "weft/fabric/weave_tally.h"

namespace weft::raytrace {
namespace {

// The replicates' streams (seed, 2^62 + bin x replicates + replicate): apart from the tasks' (seed,
// task), and each its own first state (streams that differ only in their third index start from
// the same state, and their first draws were seen to agree).
constexpr uint64_t kStraightThroughStream = uint64_t{1} << 62;

// A ray that met nothing: its cell of the table, and its direction and the start of its last
// flight (a point of its line, as a particle's when it leaves the slab).
struct StraightExit {
  uint64_t cell;
  Vec3 p, d;
};

// Where a ray of incident bin 'bin' leaves when it meets nothing: light from wi_cloth entering the
// face it faces at p's x and z, as launch() starts a particle, flown as fly() flies it (to the
// first side of the repeat or face of the slab, through the side and in again through the
// opposite one), with the scene's cheaper visibility query; none when it meets a surface or is
// lost (the trace loses a particle at its (max_wraps + 1)-th wrap).
std::optional<StraightExit> straight_exit(const RenderScene& scene, const RepeatSlab& slab,
                                          const DirectionGrid& grid, int bin, const Vec3& wi_cloth,
                                          Vec3 p, int max_wraps) {
  const Vec3 d = -cloth_to_world(wi_cloth);
  p.y = wi_cloth.z > 0 ? slab.y1 : slab.y0;
  for (int wraps = 0; wraps <= max_wraps; ++wraps) {
    const Boundaries b = boundaries_ahead(slab, p, d);
    if (scene.occluded(p, d, std::min(b.t_side, b.t_slab))) return std::nullopt;
    if (b.t_slab <= b.t_side) return StraightExit{exit_cell(grid, bin, d), p, d};
    p = wrap_through_side(slab, p, d, b.t_side, b.side);
  }
  return std::nullopt;
}

// Per cell, each replicate's sum of the power booked there; the cells in the order first met.
struct ReplicateSums {
  int replicates;
  std::vector<StraightThroughCell> cells;
  std::vector<std::vector<double>> sums;  // per cell, per replicate
  std::unordered_map<uint64_t, size_t> index;

  void add(int r, uint64_t cell, double power) {
    const auto [at, fresh] = index.try_emplace(cell, cells.size());
    if (fresh) {
      cells.push_back({cell, 0, 0});
      sums.emplace_back(replicates, 0.0);
    }
    sums[at->second][r] += power;
  }
  // The replicates' mean and the variance of that mean (their sample variance over their count).
  std::vector<StraightThroughCell> estimates() {
    for (size_t k = 0; k < cells.size(); ++k) {
      double mean = 0, var = 0;
      for (double x : sums[k]) mean += x / replicates;
      for (double x : sums[k]) var += (x - mean) * (x - mean);
      cells[k].power = mean;
      cells[k].variance = replicates > 1 ? var / (replicates - 1) / replicates : 0.0;
    }
    return std::move(cells);
  }
};

// The weave's cell of an exit (straight_through_of_bin's weave_cells).
uint64_t weave_cell(const WeaveLayout& w, const DirectionGrid& grid, int bin,
                    const StraightExit& e) {
  const uint64_t exit_bin = e.cell - static_cast<uint64_t>(bin) * grid.bins();
  return static_cast<uint64_t>(weave_position(w, e.p, e.d)) * w.coarse_bins +
         static_cast<uint64_t>(w.coarse_of_fine[exit_bin]);
}

}  // namespace

uint64_t StraightThroughPlan::rays() const {
  return static_cast<uint64_t>(replicates) * directions_per_side * directions_per_side *
         lattice_points;
}

StraightThroughPlan straight_through_plan(uint64_t particles_per_bin) {
  StraightThroughPlan plan;
  const uint64_t per_point =
      static_cast<uint64_t>(plan.replicates) * plan.directions_per_side * plan.directions_per_side;
  uint64_t a = 3, b = 5;  // consecutive Fibonacci numbers: b the first with b x per_point >= N
  while (b * per_point < particles_per_bin && b < (uint64_t{1} << 30)) {
    const uint64_t c = a + b;
    a = b, b = c;
  }
  plan.lattice_points = static_cast<int>(b);
  return plan;
}

std::vector<StraightThroughCell> straight_through_of_bin(
    const RenderScene& scene, const RepeatSlab& slab, const DirectionGrid& grid, int bin,
    const StraightThroughPlan& plan, uint64_t seed, int max_wraps, const WeaveLayout* weave,
    std::vector<StraightThroughCell>* weave_cells) {
  const int n = plan.directions_per_side, m = plan.lattice_points, reps = plan.replicates;
  const double rays_per_replicate = static_cast<double>(n) * n * m;
  ReplicateSums table{reps, {}, {}, {}}, woven{reps, {}, {}, {}};
  const bool tally_weave = weave && weave_cells;
  for (int r = 0; r < reps; ++r) {
    Rng rng(seed, kStraightThroughStream + static_cast<uint64_t>(bin) * reps + r);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        // One direction per stratum of the bin's chart square (equal solid angles), drawn
        // uniformly in it; the lattice's shift uniform over the repeat.
        const double fx = (a + rng.uniform()) / n, fy = (b + rng.uniform()) / n;
        const Vec3 wi = DirectionGrid::to_direction(grid.chart_point(bin, fx, fy));
        const double sx = rng.uniform(), sz = rng.uniform();
        const Vec3 shift{slab.x0 + slab.px * sx, 0, slab.z0 + slab.pz * sz};
        for (int k = 0; k < m; ++k) {
          const Vec3 p = lattice_point(slab, shift, k, m);
          const auto out = straight_exit(scene, slab, grid, bin, wi, p, max_wraps);
          if (!out) continue;
          const double power = std::abs(wi.z) / rays_per_replicate;
          table.add(r, out->cell, power);
          if (tally_weave) woven.add(r, weave_cell(*weave, grid, bin, *out), power);
        }
      }
  }
  if (tally_weave) *weave_cells = woven.estimates();
  return table.estimates();
}

}  // namespace weft::raytrace
