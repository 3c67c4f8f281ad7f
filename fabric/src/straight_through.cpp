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

std::vector<StraightThroughExit> straight_through_slice(const StraightThroughRays& q,
                                                        uint64_t first, uint64_t count) {
  const int n = q.plan.directions_per_side, m = q.plan.lattice_points, reps = q.plan.replicates;
  const uint64_t per_direction = static_cast<uint64_t>(m);
  const uint64_t per_replicate = static_cast<uint64_t>(n) * n * per_direction;
  const double rays_per_replicate = static_cast<double>(n) * n * m;
  std::vector<StraightThroughExit> exits;
  uint64_t j = first;
  const uint64_t end = std::min(first + count, per_replicate * static_cast<uint64_t>(reps));
  while (j < end) {
    const int r = static_cast<int>(j / per_replicate);
    Rng rng(q.seed, kStraightThroughStream + static_cast<uint64_t>(q.bin) * reps + r);
    // The replicate's stream from its start: 4 draws per direction before this slice's first.
    const uint64_t first_direction = j % per_replicate / per_direction;
    for (uint64_t d = 0; d < 4 * first_direction; ++d) (void)rng.uniform();
    for (uint64_t dir = first_direction; dir < static_cast<uint64_t>(n) * n && j < end; ++dir) {
      const int a = static_cast<int>(dir / n), b = static_cast<int>(dir % n);
      // One direction per stratum of the bin's chart square (equal solid angles), drawn
      // uniformly in it; the lattice's shift uniform over the repeat.
      const double fx = (a + rng.uniform()) / n, fy = (b + rng.uniform()) / n;
      const Vec3 wi = DirectionGrid::to_direction(q.grid.chart_point(q.bin, fx, fy));
      const double sx = rng.uniform(), sz = rng.uniform();
      const Vec3 shift{q.slab.x0 + q.slab.px * sx, 0, q.slab.z0 + q.slab.pz * sz};
      for (uint64_t k = j % per_direction; k < per_direction && j < end; ++k, ++j) {
        const Vec3 p = lattice_point(q.slab, shift, static_cast<int>(k), m);
        const auto out = straight_exit(q.scene, q.slab, q.grid, q.bin, wi, p, q.max_wraps);
        if (!out) continue;
        exits.push_back({static_cast<uint32_t>(r), out->cell,
                         q.weave ? weave_cell(*q.weave, q.grid, q.bin, *out) : 0,
                         std::abs(wi.z) / rays_per_replicate});
      }
    }
  }
  return exits;
}

struct StraightThroughBin::Sums : ReplicateSums {};

StraightThroughBin::StraightThroughBin(int replicates)
    : table_(new Sums{{replicates, {}, {}, {}}}), woven_(new Sums{{replicates, {}, {}, {}}}) {}
StraightThroughBin::~StraightThroughBin() = default;
StraightThroughBin::StraightThroughBin(StraightThroughBin&&) noexcept = default;
StraightThroughBin& StraightThroughBin::operator=(StraightThroughBin&&) noexcept = default;

void StraightThroughBin::add(const std::vector<StraightThroughExit>& exits, bool weave) {
  for (const StraightThroughExit& e : exits) {
    table_->add(static_cast<int>(e.replicate), e.cell, e.power);
    if (weave) woven_->add(static_cast<int>(e.replicate), e.weave_cell, e.power);
  }
}

std::vector<StraightThroughCell> StraightThroughBin::finish(
    std::vector<StraightThroughCell>* weave_cells) {
  if (weave_cells) *weave_cells = woven_->estimates();
  return table_->estimates();
}

std::vector<StraightThroughCell> straight_through_of_bin(
    const RenderScene& scene, const RepeatSlab& slab, const DirectionGrid& grid, int bin,
    const StraightThroughPlan& plan, uint64_t seed, int max_wraps, const WeaveLayout* weave,
    std::vector<StraightThroughCell>* weave_cells) {
  const bool tally_weave = weave && weave_cells;
  const StraightThroughRays rays{scene, slab, grid,      bin,
                                 plan,  seed, max_wraps, tally_weave ? weave : nullptr};
  StraightThroughBin sums(plan.replicates);
  sums.add(straight_through_slice(rays, 0, plan.rays()), tally_weave);
  return sums.finish(tally_weave ? weave_cells : nullptr);
}

}  // namespace weft::raytrace
