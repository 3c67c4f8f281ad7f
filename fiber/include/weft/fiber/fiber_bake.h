#pragma once
// The fiber BSDF baker: photon transport in a cylinder turned into a 4-D table over the full
// sphere of both directions, in the local frame of a surface point (x = axis t, y = b, z = outward
// normal n). Definitions, estimators and checks: docs/fiber-bsdf.md. Two routes estimate the same
// table: the direct one (a parallel beam over the whole lit cylinder) and the paper's (its BSSRDF,
// bssrdf.h, summed over the lit cells).
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/fiber/fiber_physics.h"

namespace weft {

// How the direct route draws a photon's entry (its light direction, its impact parameter across
// the fiber and its surface-lobe directions): independent uniforms (random), or per task of
// photons the points of a randomised Sobol' sequence (core/sobol.h), which stratifies them while
// each photon's entry stays uniform, so the estimate stays unbiased (docs/fiber-bsdf.md).
enum class FiberEntrySampling : uint8_t { kRandom, kStratified };
inline constexpr NameTable<FiberEntrySampling, 2> kFiberEntrySamplings = {{
    {FiberEntrySampling::kRandom, "random", "random entries"},
    {FiberEntrySampling::kStratified, "stratified", "stratified entries"},
}};
const char* fiber_entry_sampling_name(FiberEntrySampling e);  // "random", "stratified"
// Parses a name of kFiberEntrySamplings; weft::Error naming 'field' otherwise.
FiberEntrySampling parse_fiber_entry_sampling(const std::string& name, const std::string& field);

struct FiberBakeSettings {
  int resolution = 8;    // R: R x R equal-area bins per hemisphere and direction (DirectionGrid)
  uint64_t photons = 0;  // photons per band (callers say how many)
  uint64_t seed = 0;
  int threads = 0;  // 0 = all cores
  uint64_t photons_per_task = 4096;
  // Optional far-field tally of the direct route (0 = off): the fiber's scattering per unit
  // length binned by the axial cosines of both directions and their azimuth difference about the
  // axis, the reciprocal quantity (docs/fiber-bsdf.md).
  int far_field_s_bins = 0;
  int far_field_psi_bins = 0;
  FiberEntrySampling entry = FiberEntrySampling::kRandom;  // the direct route's entries
  // Whether the surface lobe's draws are booked into the cells (false: the table adds the lobe
  // analytically, FiberSurfaceLobe::kAnalytic); they are counted in the books either way.
  bool book_surface = true;
};

// The cosine-weighted cell averages of one band: value[i * R^2 + o] with i the incident (light)
// direction bin and o the exit (view) bin, 1/sr. Also the raw tallies needed by the checks.
struct FiberBandTable {
  int resolution = 0;
  std::vector<double> f;             // R^4 cell averages (1/sr)
  std::vector<double> weighted_sum;  // R^4 sums of f |cos_i| |cos_o| over the cell pair (sr^2)
  // Energy, as fractions of the light hitting the fiber. Per photon the books balance exactly:
  //   exit + absorbed + roulette_net + lost - surface_sampling_excess - expected_exit_excess = 1
  // (to rounding), where surface_sampling_excess = mean(sampled surface weight - tabulated surface
  // albedo) has mean zero: the surface lobe is sampled, the part that enters uses the lobe's
  // albedo; expected_exit_excess likewise for next-event estimation of exits (transport.h), zero
  // without it. 'exit' is what the table holds.
  double exit_fraction = 0;      // everything that leaves (surface + volume)
  double surface_fraction = 0;   // of which reflected by the surface lobe
  double absorbed_fraction = 0;  // absorbed inside, as traced
  double roulette_net = 0;
  double lost_fraction = 0;  // weight the interior tracer gave up on (reported, not hidden)
  double surface_sampling_excess = 0;
  double expected_exit_excess = 0;
  double energy_balance() const {
    return exit_fraction + absorbed_fraction + roulette_net + lost_fraction -
           surface_sampling_excess - expected_exit_excess;
  }
  // Far field (if asked): [s_i bin][s_o bin][azimuth-difference bin], integrals of F over the
  // bins (sr^2 per unit length in fiber radii); reciprocity: [a][b][c] = [b][a][n - 1 - c].
  std::vector<double> far_field;
  uint64_t photons = 0;  // photons traced (fewer than asked if cancelled)
  uint64_t scattering_events = 0;
  bool cancelled = false;
};

// The direct route: a parallel beam over the whole lit cylinder.
FiberBandTable bake_fiber_band_direct(const FiberBandPhysics& fiber,
                                      const FiberBakeSettings& settings,
                                      const ProgressCallback& progress);

// The paper's route: the BSSRDF (bssrdf.h) for incident directions over A's lit hemisphere in
// (s = axial cosine, azimuth about the axis) bins, summed over the axial offset, then the paper's
// sum over lit cells A_i for each table cell.
struct BssrdfRouteSettings {
  int u_bins = 180;  // offsets around the axis
  // The BSSRDF is averaged over each incident bin, which blurs how the exit direction follows the
  // incident one: a first-order bias in the bin width, largest for clear fibers (measured in
  // docs/fiber-bsdf.md). 64 x 64 keeps it below the noise of scattering fibers.
  int incident_s_bins = 64;
  int incident_psi_bins = 64;
  int cell_quadrature = 16;  // points per side when integrating over a table bin of wi
};
FiberBandTable bake_fiber_band_bssrdf(const FiberBandPhysics& fiber,
                                      const FiberBakeSettings& settings,
                                      const BssrdfRouteSettings& route,
                                      const ProgressCallback& progress);

// The fiber's mirror symmetries (docs/fiber-bsdf.md), f(M w_i, M w_o) = f(w_i, w_o) for M flipping
// the axis t, the binormal b or both, applied to R^4 cell-pair sums (weighted sums or averages):
// each cell pair becomes the mean of its four images. Exact for the fiber, so an estimate folded
// this way is as unbiased as before and pools four cells' photons.
std::vector<double> fold_fiber_mirror_symmetry(int resolution, const std::vector<double>& cells);

// Sum of f |cos_i| |cos_o| over all cell pairs: pi * (1 - absorbed) for a correct table.
double fiber_table_energy(const FiberBandTable& table);

}  // namespace weft
