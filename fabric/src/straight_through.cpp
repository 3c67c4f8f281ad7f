#include "weft/fabric/straight_through.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "weft/core/rng.h"

namespace weft::raytrace {
namespace {

// The replicates' streams (seed, 2^62 + bin x replicates + replicate): apart from the tasks' (seed,
// task), and each its own first state (streams that differ only in their third index start from
// the same state, and their first draws were seen to agree).
constexpr uint64_t kStraightThroughStream = uint64_t{1} << 62;

// The cell a ray of incident bin 'bin' leaves through when it meets nothing: light from wi_cloth
// entering the face it faces at p's x and z, as launch() starts a particle, flown as fly() flies
// it (to the first side of the repeat or face of the slab, through the side and in again through
// the opposite one), with the scene's cheaper visibility query; none when it meets a surface or is
// lost (the trace loses a particle at its (max_wraps + 1)-th wrap).
std::optional<uint64_t> straight_exit(const RenderScene& scene, const RepeatSlab& slab,
                                      const DirectionGrid& grid, int bin, const Vec3& wi_cloth,
                                      Vec3 p, int max_wraps) {
  const Vec3 d = -cloth_to_world(wi_cloth);
  p.y = wi_cloth.z > 0 ? slab.y1 : slab.y0;
  for (int wraps = 0; wraps <= max_wraps; ++wraps) {
    const Boundaries b = boundaries_ahead(slab, p, d);
    if (scene.occluded(p, d, std::min(b.t_side, b.t_slab))) return std::nullopt;
    if (b.t_slab <= b.t_side) return exit_cell(grid, bin, d);
    p = wrap_through_side(slab, p, d, b.t_side, b.side);
  }
  return std::nullopt;
}

// Adds 'power' to the replicate's sum in 'cell'.
void add_to(std::vector<StraightThroughCell>& cells, std::vector<std::vector<double>>& sums,
            int replicates, int r, uint64_t cell, double power) {
  size_t k = 0;
  while (k < cells.size() && cells[k].cell != cell) ++k;
  if (k == cells.size()) {
    cells.push_back({cell, 0, 0});
    sums.emplace_back(replicates, 0.0);
  }
  sums[k][r] += power;
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

std::vector<StraightThroughCell> straight_through_of_bin(const RenderScene& scene,
                                                         const RepeatSlab& slab,
                                                         const DirectionGrid& grid, int bin,
                                                         const StraightThroughPlan& plan,
                                                         uint64_t seed, int max_wraps) {
  const int n = plan.directions_per_side, m = plan.lattice_points, reps = plan.replicates;
  const double rays_per_replicate = static_cast<double>(n) * n * m;
  std::vector<StraightThroughCell> cells;
  std::vector<std::vector<double>> sums;  // per cell, per replicate
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
          if (const auto cell = straight_exit(scene, slab, grid, bin, wi, p, max_wraps))
            add_to(cells, sums, reps, r, *cell, std::abs(wi.z) / rays_per_replicate);
        }
      }
  }
  // The replicates' mean and the variance of that mean (their sample variance over their count).
  for (size_t k = 0; k < cells.size(); ++k) {
    double mean = 0, var = 0;
    for (double x : sums[k]) mean += x / reps;
    for (double x : sums[k]) var += (x - mean) * (x - mean);
    cells[k].power = mean;
    cells[k].variance = reps > 1 ? var / (reps - 1) / reps : 0.0;
  }
  return cells;
}

}  // namespace weft::raytrace
