#pragma once
// The ray trace's second tally (FabricRaytraceOptions::weave_positions_u): the exits binned also by
// where they leave the cloth within its repeat, at a coarse angular resolution, giving the weave
// table (materials/weave_table.h, docs/fabric-bsdf.md "The weave table").
//
// An exit's position is where its line (the particle's last straight flight, extended both ways)
// crosses the cloth's mid-plane, the plane halfway through the slab the ray trace uses, wrapped
// into the repeat: the renderer puts the mesh surface at the mid-plane, so this is where an
// observer sees the exit leave. Cell (iu, iv) of positions_u x positions_v covers the fractions
// [iu, iu + 1) / positions_u along the warp (x, the table's x) and [iv, iv + 1) / positions_v along
// the table's y (= -z of the sample) of the repeat, counted from its corner at the least x and
// the greatest z (the sample's repeat is centred on the origin: x = -Px / 2, z = +Pz / 2).
//
// Coarse bins: a fine bin of the fabric table belongs to the coarse bin that holds its centre, so
// the coarse cells are unions of the table's cells (exactly so when the coarse R divides the
// table's) and the mean over the positions of what was booked is the table's coarse average.
#include <cstdint>
#include <span>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/vec.h"
#include "weft/fabric/fabric_raytrace.h"

namespace weft {

// The size of a weave table: positions, coarse R and the repeat (what its assembly needs besides
// the fabric table and the bins' books).
struct WeaveShape {
  int positions_u = 0, positions_v = 0, resolution = 0;
  double repeat_u_m = 0, repeat_v_m = 0;
  bool on() const { return positions_u > 0; }
  int positions() const { return positions_u * positions_v; }
};

// The weave options of a ray trace (FabricRaytraceOptions::validate): weft::Error naming the field.
void validate_weave_options(const FabricRaytraceOptions& o);

// The coarse bin of fine bin 'bin' (the one holding its centre), for every fine bin.
std::vector<int> coarse_bins_of(const DirectionGrid& fine, const DirectionGrid& coarse);

// The fabric table's cosine-weighted average over each coarse cell pair, per channel:
// [coarse wi][coarse wo][channel]. What the weave's booked values average to over the positions.
std::vector<double> coarse_table_average(const TabulatedBsdfTable& table, int coarse_resolution);

// Bytes the weave tally holds during a ray trace and in its result (its per-bin sums and the
// computed straight-through part's, the books' copies and the table), for a front end's memory
// budget; 0 when positions_u is 0.
double weave_tally_bytes(int table_resolution, int weave_resolution, int positions_u,
                         int positions_v, int channels);

// From the bins' weave books (FabricBinBooks::weave_values, weave_noise2), summed in bin order:
// result.weave (the modulation), result.weave_mean and result.weave_relative_noise, and the
// weave's metadata (describe_weave). Nothing when the shape is off.
void weave_totals(const WeaveShape& shape, FabricRaytraceResult& result);
// The weave's metadata: the fabric table's (but the names the weave's format reserves), and
// "fabric_checksum", the table it modulates. Again whenever the table's metadata changes.
void describe_weave(const TabulatedBsdfTable& table, WeaveTable& weave);

namespace raytrace {

// Where the weave tally puts an exit: the fine-to-coarse bin map and the repeat (world frame).
struct WeaveLayout {
  WeaveShape shape;
  int channels = 0, table_resolution = 0, fine_bins = 0, coarse_bins = 0;
  std::vector<int> coarse_of_fine;
  double x0 = 0, z0 = 0, px = 0, pz = 0, y_mid = 0;
  // Doubles per incident bin: positions x coarse outgoing bins x channels.
  size_t per_bin() const;
};
// The layout of a run's options on a repeat [x0, x0 + px] x [z0, z0 + pz], slab [y0, y1].
WeaveLayout weave_layout(const FabricRaytraceOptions& o, int channels, double x0, double z0,
                         double px, double pz, double y0, double y1);

// The position cell of an exit along d whose line passes through p.
int weave_position(const WeaveLayout& w, const Vec3& p, const Vec3& d);

// A task's weave exits; those of one sample unit (tagged by the unit's first exit of the table's
// tally, Life::first_exit) are merged per cell of WeaveSums, as the table's per its cell, so that
// the variance is that of the unit's total there.
struct WeaveExit {
  uint64_t cell;   // (incident bin, position, coarse outgoing bin): WeaveSums' index / channels
  uint64_t unit;   // the sample unit's tag
  uint32_t first;  // index of its channel weights
};
struct WeaveExits {
  std::vector<WeaveExit> exits;
  std::vector<double> weights;
};
// An exit of a particle of incident bin 'bin' into the table's outgoing bin 'exit_bin', along d
// with its line through p.
void tally_weave_exit(const WeaveLayout& w, WeaveExits& tally, uint64_t unit, int bin, int exit_bin,
                      const Vec3& p, const Vec3& d, std::span<const double> weights);

// Per (fine incident bin, position, coarse outgoing bin, channel), over the sample units: the sum
// of their weights and of their squares.
struct WeaveSums {
  std::vector<double> sum, sum2;
};
WeaveSums weave_sums_for(const WeaveLayout& w);
void add_weave_task(const WeaveLayout& w, const WeaveExits& tally, WeaveSums& sums);
// Each bin's weave books (FabricBinBooks::weave_values, weave_noise2) from the sums over per_bin
// particles per bin in units[bin] sample units, and the computed straight-through light's part
// (FabricRaytraceOptions::straight_through exact; empty: none), whose sum is added to the
// particles' and whose sum2 is that sum's variance, added to the noise (as the table's cell).
void weave_bin_books(const WeaveLayout& w, const WeaveSums& sums, const WeaveSums& exact,
                     uint64_t per_bin, const std::vector<uint64_t>& units,
                     FabricRaytraceResult& result);

}  // namespace raytrace
}  // namespace weft
