// The ray trace's table from its sums (private to fabric_raytrace.cpp and its parts): the checks of
// the tables a run traces with, the sums' tabulation with its standard error, the sheen's booked
// window and the table's metadata. Apart from the particles' tracing, which it does not need.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/rng.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/materials/half_vector_lobe.h"

namespace weft::raytrace {

// A fiber sends out at most the light that hits it: a table's total albedo (the bake's exit
// fraction) is at most 1, within kFiberAlbedoAllowance (fiber_table_bake.h). Above it, path
// weights grow from fiber to fiber, and the trace would run for minutes before they overflow (a
// synthetic table of total albedo 1.9 did: tens of CPU minutes), so it is refused before any work.
void check_fiber_energy(const TabulatedBsdfTable& t, const std::string& field);

// A table that draws or weighs the trace's steps in place of another fiber table (a proposal, or
// the fiber re-weighting recorded paths): valid, a fiber table of the other's resolution and
// channels, since the steps index both alike, and no more than lossless.
void check_fiber_stand_in(const TabulatedBsdfTable& t, int resolution, int channels,
                          const std::string& field, const char* mismatch);

// The proposal a run's paths are drawn from: a stand-in for the traced fiber table.
void check_proposal(const TabulatedBsdfTable& proposal, const TabulatedBsdfTable& fiber);

// The exits' sums of weights and of their squares, per table value (cell pair and channel).
struct CellSums {
  std::vector<double> sum, sum2;
};

// A task's exits into the sums, and its bins' books into the result.
void add_task(const Tally& t, int nc, CellSums& sums, FabricRaytraceResult& result);

// The table from the sums over per_bin particles per incident bin and the exact part (its values'
// sums and their variance, per cell pair; empty: none), its standard error, and each bin's noise
// and signal.
void tabulate(const CellSums& sums, const CellSums& exact, const DirectionGrid& grid, int nc,
              uint64_t per_bin, const std::vector<uint64_t>& units, FabricRaytraceResult& result);

// The table's metadata: how it was traced, from which sample and fiber table.
void describe(const WovenSample& sample, const TabulatedBsdfTable& fiber,
              const FabricRaytraceOptions& o, TabulatedBsdfTable& table);

// Per-yarn tables in the metadata: in place of the one fiber's checksum and spec, per table
// "name: checksum (spec name)", "; " between tables, how many of the fibers' yarns take each
// (a draft has up to 40 000 yarns: counts, not the map) and each mesh's table.
void describe_per_yarn(const FiberTables& f, TabulatedBsdfTable& table);

// The sheen is booked apart only where the exact lobe is traced, for the whole table (its cell
// averages blend neighbouring light bins) and not into recorded paths.
void check_sheen_trace(const FabricRaytraceOptions& o, int bins, bool exact_lobe, bool record);

// The sheen's booked sums (after the table's cells in 'sums', channels per window bin) as Q =
// sum / (particles of the light bin x window bin solid angle x mean wi . h) (HalfVectorLobe::
// mean_projections: the light each (light bin, window bin) booked is the light its cell averages
// carry), added to the table: its cell averages join the cells, which hold the rest.
void add_booked_sheen(const CellSums& sums, const std::vector<uint64_t>& per_stratum, int threads,
                      HalfVectorLobe sheen, TabulatedBsdfTable& table);

// A narrow light's directions and its plane of incidence's exits (NarrowLight), in the cloth frame.
struct LightPlane {
  NarrowLight light;
  Vec3 wi, u, v;  // towards the light; the plane's horizontal towards it; n x u
  explicit LightPlane(const NarrowLight& light);
  // A direction towards the light, uniform over the cone's solid angle (two draws, also when the
  // beam is collimated, so that the stream does not depend on the cone's width).
  Vec3 draw(Rng& rng) const;
  // The plane_f bin of a reflected exit wo, -1 outside the band or the bins; into 'factor' what its
  // weights are multiplied by to book f over the bin's (theta', phi'): 1 / (wo.z cos theta').
  int bin_of(const Vec3& wo, double& factor) const;
};

// The plane's sums (after the table's cells in 'sums', from value first_value on) as plane_f and
// its standard error: over the power launched and the bin's theta' x phi' extent, and 'units'
// independent sample units.
void tabulate_plane(const CellSums& sums, size_t first_value, const LightPlane& plane, int nc,
                    double launched, uint64_t units, FabricRaytraceResult& result);

}  // namespace weft::raytrace
