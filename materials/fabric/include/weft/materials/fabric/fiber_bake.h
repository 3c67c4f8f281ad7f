#pragma once
// The fiber BSDF baker: photon transport in a smooth cylinder turned into a 4-D table over the
// full sphere of both directions, in the local frame of a surface point (x = axis t, y = b,
// z = outward normal n). Definitions, estimator and checks: docs/fiber-bsdf.md.
#include <cstdint>
#include <functional>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/core/vec.h"

namespace weft {

// A photon leaving the fiber: position on the surface (world, axis = x), direction outside
// (unit, away from the fiber), weight.
struct FiberExit {
  Vec3 position;
  Vec3 direction;
  double weight = 0;
};

// Receives exits while a photon is traced.
using FiberExitSink = std::function<void(const FiberExit&)>;

// Traces one photon that has just been refracted into the fiber at surface point 'p' (world
// frame, axis x, radius R) travelling along unit 'd' with weight 'w', reporting every exit.
// Must be deterministic given rng.
struct FiberTraceResult {
  uint64_t scattering_events = 0;
  double absorbed_weight = 0;
  double roulette_net = 0;  // weight removed by Russian roulette minus weight added (mean 0)
  double lost_weight = 0;   // weight the tracer could not follow (e.g. an interaction cap)
};
using FiberInteriorTracer = std::function<FiberTraceResult(const Vec3& p, const Vec3& d, double w,
                                                           Rng& rng, const FiberExitSink& sink)>;

// The rough surface seen from outside, in the local frame of the hit point (z = normal).
struct FiberSurfaceModel {
  // Samples the surface-reflected direction for light from 'w_light' (z > 0): returns false if
  // none; else sets the reflected direction and its weight f * cos / pdf.
  std::function<bool(const Vec3& w_light, Vec2 u, double u_lobe, Vec3* w_out, double* weight)>
      sample;
  // Directional albedo of the surface lobe for light at cos theta (its complement enters).
  std::function<double(double cos_theta)> albedo;
};

struct FiberGeometry {
  double radius_um = 10;
  double n_fiber = 1.557;  // index inside
  double n_outside = 1.0;
};

struct FiberBakeSettings {
  int resolution = 8;         // R: R x R equal-area bins per direction over the sphere
  uint64_t photons = 100000;  // photons per band
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  uint64_t photons_per_task = 4096;
  // Optional far-field tally of the direct route (0 = off): the fiber's scattering per unit
  // length binned by the axial cosines of both directions and their azimuth difference about the
  // axis, the reciprocal quantity (docs/fiber-bsdf.md).
  int far_field_s_bins = 0;
  int far_field_psi_bins = 0;
};

// The cosine-weighted cell averages of one band: value[i * R^2 + o] with i the incident (light)
// direction bin and o the exit (view) bin, 1/sr. Also the raw tallies needed by the checks.
struct FiberBandTable {
  int resolution = 0;
  std::vector<double> f;             // R^4 cell averages (1/sr)
  std::vector<double> weighted_sum;  // R^4 sums of f |cos_i| |cos_o| over the cell pair (sr^2)
  // Energy, as fractions of the light hitting the fiber. Per photon the books balance exactly:
  //   exit + absorbed + roulette_net + lost - surface_sampling_excess = 1   (to rounding),
  // where surface_sampling_excess = mean(sampled surface weight - tabulated surface albedo) has
  // mean zero: the surface lobe is sampled, the part that enters uses the lobe's albedo.
  double exit_fraction = 0;      // everything that leaves (surface + volume)
  double surface_fraction = 0;   // of which reflected by the surface lobe
  double absorbed_fraction = 0;  // absorbed inside, as traced
  double roulette_net = 0;
  double lost_fraction = 0;  // weight the interior tracer gave up on (reported, not hidden)
  double surface_sampling_excess = 0;
  double energy_balance() const {
    return exit_fraction + absorbed_fraction + roulette_net + lost_fraction -
           surface_sampling_excess;
  }
  // Far field (if asked): [s_i bin][s_o bin][azimuth-difference bin], integrals of F over the
  // bins (sr^2 per unit length in fiber radii); reciprocity: [a][b][c] = [b][a][n - 1 - c].
  std::vector<double> far_field;
  uint64_t photons = 0;  // photons traced (fewer than asked if cancelled)
  uint64_t scattering_events = 0;
  bool cancelled = false;
};

// D_k = integral over bin k of |cos theta| d omega, for the R x R equal-area bins.
std::vector<double> cosine_weighted_bin_areas(int resolution);

// Bin index of a unit direction on the R x R equal-area square.
int direction_bin(const Vec3& d, int resolution);

// The direct route: a parallel beam over the whole lit cylinder. 'stage' names progress.
FiberBandTable bake_fiber_band_direct(const FiberGeometry& geometry,
                                      const FiberSurfaceModel& surface,
                                      const FiberInteriorTracer& tracer,
                                      const FiberBakeSettings& settings,
                                      const ProgressCallback& progress);

// The paper's route: photons enter a small area A from directions over its lit hemisphere; exits
// are binned by their angular offset around the axis from A (u), summed over the axial offset
// (v; shift invariance), and by exit direction, giving the BSSRDF; the BRDF of a cell is then the
// paper's sum over lit cells A_i. Grid sizes: u bins around the circle, incident bins in
// (s = axial cosine, azimuth about the axis).
struct BssrdfGrid {
  int u_bins = 180;
  // The BSSRDF is averaged over each incident bin, which blurs how the exit direction follows the
  // incident one: a first-order bias in the bin width, largest for clear fibers (measured in
  // docs/fiber-bsdf.md). 64 x 64 keeps it below the noise of scattering fibers.
  int incident_s_bins = 64;
  int incident_psi_bins = 64;
  int cell_quadrature = 16;  // points per side when integrating over a table bin of wi
};
FiberBandTable bake_fiber_band_bssrdf(const FiberGeometry& geometry,
                                      const FiberSurfaceModel& surface,
                                      const FiberInteriorTracer& tracer,
                                      const FiberBakeSettings& settings, const BssrdfGrid& grid,
                                      const ProgressCallback& progress);

// Sum of f |cos_i| |cos_o| over all cell pairs: pi * (1 - absorbed) for a correct table.
double fiber_table_energy(const FiberBandTable& table);

}  // namespace weft
