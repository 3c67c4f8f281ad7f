#pragma once
// The fiber-level ray trace's paths under a proposal (FabricRaytraceOptions::proposal), recorded
// once and re-weighted for other fiber tables without tracing again. Under a proposal every choice
// of a particle's life (B' or B'', exit cell and direction, roulette, splitting) depends on the
// proposal alone, and the straight-through light (straight_through.h) on no table at all, so at a
// fixed seed the traced table changes only the weights: each scattering multiplies them by f over
// the step's probability, a yarn tube's crossing by the table's line albedo over its point
// albedos, roulette and splitting divide them. The record keeps those steps in the order the
// trace took them (per task of the batch) with the straight-through light's sums, and the
// re-weighting replays them with the other table's f: its table and standard error have the bits
// of raytrace_fabric_table with that table and the proposal, at any thread count, at the cost of a
// few multiplications per scattering instead of the flights (weft verify --fit's inner model,
// docs/verify.md).
#include <cstdint>
#include <string>
#include <vector>

#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/line_albedo.h"

namespace weft {

namespace raytrace {
struct Tally;  // raytrace_steps.h

// One step of a recorded life that touches the weights, in trace order.
struct PathOp {
  enum Kind : uint8_t {
    launch,   // a particle launched with weight x in every channel, pending alone
    pop,      // the next pending particle (or copy) is followed
    scatter,  // times f(a, b, c) / x: light bin a, exit cell b of the fiber table, x the mean pdf
    tube,     // a yarn tube's crossing: axial cosine x, point bins a and b (b < 0: one point)
    divide,   // divided by x (Russian roulette's survival)
    split,    // divided by a, a - 1 copies left pending
    book,     // an exit into fabric table cell a
    unit,     // a sample unit (a particle, or a launch block's part of a task) starts
  };
  double x = 0;
  int64_t a = 0;
  int32_t b = 0;
  Kind kind = launch;
};

// Replays one task's steps with 'fiber' (and its yarn tubes' line albedo 'tube', at yarn detail)
// into 'tally', as the trace booked them.
void replay_path_ops(const std::vector<PathOp>& ops, const TabulatedBsdfTable& fiber,
                     const LineAlbedo* tube, int channels, Tally& tally);
}  // namespace raytrace

// A ray trace's paths under its proposal, for re-weighting (reweight_fabric_paths).
struct RecordedFabricPaths {
  FabricRaytraceOptions options;  // the trace's (its proposal pointer cleared)
  std::string proposal_checksum;
  int fiber_resolution = 0, channels = 0;
  bool yarn_tubes = false;
  std::vector<std::vector<raytrace::PathOp>> tasks;  // per task of the trace's batch
  std::vector<double> exact_sum, exact_sum2;         // the straight-through light's, per cell pair
  std::vector<uint64_t> units;                       // sample units per incident bin
  FabricRaytraceResult traced;  // the recorded trace's result (the proposal's own table)
};

// The ray trace of raytrace_fabric_table with the proposal 'proposal' traced as its own table
// (options.proposal is taken to be &proposal), its steps recorded. weft::Error naming the field for
// what the record does not replay: a trace in pieces (first_bin, bin_count), the next-event
// estimate, the weave tally.
RecordedFabricPaths record_fabric_paths(const WovenSample& sample,
                                        const TabulatedBsdfTable& proposal,
                                        const FabricRaytraceOptions& options);

// The fabric table of the recorded trace's paths re-weighted for 'fiber': table, standard error,
// relative noise and the counts (particles, scatterings, wraps, splits, roulette kills) have the
// bits of raytrace_fabric_table(sample, fiber, options with the proposal); the energy books
// (exited, absorbed, lost, roulette_net) are not replayed and stay 0. 'threads' as the trace's
// (0: all cores; the bits do not depend on it). The table is checked as the trace checks it
// (a fiber table of the proposal's resolution and channels, energy), weft::Error naming "fiber".
FabricRaytraceResult reweight_fabric_paths(const RecordedFabricPaths& paths,
                                           const TabulatedBsdfTable& fiber, int threads = 0);

}  // namespace weft
