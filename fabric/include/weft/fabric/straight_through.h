#pragma once
// The light that passes straight through the cloth (FabricRaytraceOptions::straight_through):
// a particle of incident bin i that meets no fiber leaves the slab along its launch direction,
// into one cell per incident bin, with its launch weight |cos theta_i| in every channel. Sampled,
// that cell is a hit or a miss of the gaps between the fibers per particle, most of a dense
// cloth's noise (docs/PERFORMANCE.md). Its expectation per launched particle,
// E[|cos theta_i| 1{meets nothing} 1{cell}] over the launch's law (a direction uniform over the
// bin, an entry point uniform over the repeat), is computed here instead by randomized quasi-Monte
// Carlo over that same law: the bin's chart square cut into strata, one direction drawn in each,
// and per direction the entry points of a randomly shifted rank-1 lattice over the repeat
// (lattice_point). Each ray has the launch's law, so the estimate is unbiased; independently
// drawn replicates give its variance, which the table's standard error includes. The particles
// then book only what meets a fiber: E[their part] + this = the sampled estimator's expectation.
#include <cstdint>
#include <memory>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/scenes/render_scene.h"

namespace weft::raytrace {

// The rays of one incident bin's estimate: replicates x directions_per_side^2 directions x
// lattice_points entry points. The directions are what the estimate's variance is made of (the
// gaps' shadows move across the repeat as the direction tilts): on the bundled poplin at about
// 60 000 rays per bin, 4 x 4 directions with 987 points each left 8 times the variance of 8 x 8
// with 233 (docs/PERFORMANCE.md).
struct StraightThroughPlan {
  int replicates = 4, directions_per_side = 8, lattice_points = 5;
  uint64_t rays() const;
};
// At least as many rays as the bin launches particles (a ray stops at the first fiber it meets:
// it costs about a tenth of a particle on the bundled poplin), 5 points per direction at least.
// The lattice sizes are Fibonacci numbers (lattice_point: the golden-ratio lattice covers the
// repeat evenly).
StraightThroughPlan straight_through_plan(uint64_t particles_per_bin);

// A cell of the fabric table (incident bin * bins + outgoing bin) and the straight-through power
// per launched particle the estimate books there, with the variance of that estimate.
struct StraightThroughCell {
  uint64_t cell = 0;
  double power = 0, variance = 0;
};
struct WeaveLayout;  // weave_tally.h

// Incident bin 'bin''s estimate: its rays follow the particles' flight (fly, through the repeat's
// sides) to the first surface or out of the slab; a particle that wraps more than max_wraps times
// is lost, as in the trace. Random numbers from the streams (seed, 2^62 + bin x replicates +
// replicate): the same bits in a whole run and in any piece of it.
// With the weave tally (weave and weave_cells given): the same rays' power also by where each
// ray's line crosses the cloth's mid-plane (weave_position, as a particle's exit), into
// *weave_cells: cell = position x the weave's coarse bins + the coarse outgoing bin (the bin's
// part of WeaveSums over the channels), with its replicates' variance. It draws nothing more.
std::vector<StraightThroughCell> straight_through_of_bin(
    const RenderScene& scene, const RepeatSlab& slab, const DirectionGrid& grid, int bin,
    const StraightThroughPlan& plan, uint64_t seed, int max_wraps,
    const WeaveLayout* weave = nullptr, std::vector<StraightThroughCell>* weave_cells = nullptr);

// The same estimate in slices of its rays, so that a run can split a bin's rays into tasks of
// bounded work (and poll for a cancel between them) with the same bits: a bin's rays are numbered
// replicate by replicate, direction by direction, entry point by entry point; a slice traces rays
// [first, first + count) into the exits it books, and StraightThroughBin::add takes the slices in
// ray order and books them as straight_through_of_bin does.
struct StraightThroughRays {
  const RenderScene& scene;
  const RepeatSlab& slab;
  const DirectionGrid& grid;
  int bin;
  StraightThroughPlan plan;
  uint64_t seed;
  int max_wraps;
  const WeaveLayout* weave = nullptr;  // with the weave tally: each exit's weave cell too
};
struct StraightThroughExit {
  uint32_t replicate = 0;
  uint64_t cell = 0, weave_cell = 0;
  double power = 0;
};
std::vector<StraightThroughExit> straight_through_slice(const StraightThroughRays& rays,
                                                        uint64_t first, uint64_t count);
class StraightThroughBin {
 public:
  explicit StraightThroughBin(int replicates);
  ~StraightThroughBin();
  StraightThroughBin(StraightThroughBin&&) noexcept;
  StraightThroughBin& operator=(StraightThroughBin&&) noexcept;
  void add(const std::vector<StraightThroughExit>& exits, bool weave);
  // The bin's cells (straight_through_of_bin's result) and, with the weave tally, its weave cells.
  std::vector<StraightThroughCell> finish(std::vector<StraightThroughCell>* weave_cells);

 private:
  struct Sums;
  std::unique_ptr<Sums> table_, woven_;
};

}  // namespace weft::raytrace
