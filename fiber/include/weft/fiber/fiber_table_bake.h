#pragma once
// Bakes a fiber spec into a fiber BSDF table: Mie medium per band -> photon transport in the
// cylinder -> cosine-weighted cell averages (docs/fiber-bsdf.md) plus the Cook-Torrance surface
// lobe, for every band, stored as a spectral (33 bands) or RGB table.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/fiber/fiber_bake.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

enum class FiberBakeRoute { kDirect, kBssrdf };
inline constexpr NameTable<FiberBakeRoute, 2> kFiberBakeRoutes = {{
    {FiberBakeRoute::kDirect, "direct", "direct (parallel beam)"},
    {FiberBakeRoute::kBssrdf, "bssrdf", "BSSRDF (the paper's route)"},
}};
// The table's bands: spectral (33 bands) or RGB (FiberTableBakeOptions::spectral).
inline constexpr NameTable<bool, 2> kFiberBakeBands = {{
    {true, "spectral", "33 bands, 390-710 nm"},
    {false, "rgb", "linear sRGB, D65"},
}};

// How the fiber's first-surface reflection (the smooth boundary's Cook-Torrance lobe, docs/
// fiber-bsdf.md) enters the table. sampled: the photons' lobe draws are booked into the cells like
// every exit. analytic: the cells get the lobe's cell averages by quadrature instead and the
// table names the lobe (materials/surface_lobe.h), so a reader can evaluate and sample it
// exactly: on a smooth filament (GGX alpha 0.1) the lobe is narrower than an R 8 table's bins.
// Both tables hold the same f in expectation; analytic needs the smooth boundary and the direct
// route.
enum class FiberSurfaceLobe : uint8_t { kSampled, kAnalytic };
inline constexpr NameTable<FiberSurfaceLobe, 2> kFiberSurfaceLobes = {{
    {FiberSurfaceLobe::kSampled, "sampled", "the photons' draws, binned"},
    {FiberSurfaceLobe::kAnalytic, "analytic", "named beside the cells, cells by quadrature"},
}};
// The lobe of a table baked with FiberSurfaceLobe::kAnalytic: the spec's roughness, the host's
// index per band (spectral) or at 610, 550 and 460 nm (RGB: the index changes the lobe's Fresnel
// by well under 1 % across a channel).
SurfaceLobe fiber_surface_lobe(const FiberSpec& spec, bool spectral);

// Upper bound on photons per band that any front end accepts (about a day of work per band).
inline constexpr uint64_t kMaxPhotonsPerBand = uint64_t{1} << 40;

// The defaults here are the only ones: `weft bake fiber` and the bake cache start from them.
struct FiberTableBakeOptions {
  int resolution = 8;  // R x R equal-area bins per direction
  uint64_t photons_per_band = 50000;
  uint64_t seed = 1;
  int threads = 0;       // 0 = all cores; results do not depend on it
  bool spectral = true;  // 33 bands, else linear sRGB (D65) from the 33 bands
  FiberBakeRoute route = FiberBakeRoute::kDirect;
  uint64_t max_events_per_photon = 10'000'000;  // beyond it the weight is reported as lost
  // How the fiber's interior treats absorption (transport.h). absorption_weight makes the table a
  // smooth function of the absorption at a fixed seed (paths do not depend on it): weft verify
  // --fit's inner bake (docs/verify.md). Both are unbiased; the default keeps its bits.
  WeightMode weight_mode = WeightMode::implicit_capture;
  // Photons are traced in this many passes over all bands; an interrupted bake keeps every
  // finished pass (results depend on it, not on threads).
  uint64_t passes = 8;
  // Variance reduction (docs/fiber-bsdf.md, "Fewer photons for the same noise"); all unbiased.
  // The defaults are the fewest photons for a table error measured (docs/PERFORMANCE.md):
  // next-event estimation, mirror folding, four surface samples and stratified entries, 20x fewer
  // photons than the plain bake and about 4x the CPU per photon; a next-event table is scaled to
  // the walk's own exits, so its energy is a plain bake's (FiberBandSummary::energy_scale).
  // How exits are tallied: one by one (plain), or by next-event estimation (smooth boundary only).
  FiberExitEstimator estimator = FiberExitEstimator::kNextEvent;
  // Average every cell pair with its images under the fiber's mirror symmetries.
  bool mirror_fold = true;
  // Surface-lobe directions drawn per photon (smooth boundary only; FiberSurfaceModel::samples).
  int surface_samples = 4;
  // How photons' entries are drawn (FiberEntrySampling; direct route only).
  FiberEntrySampling entry = FiberEntrySampling::kStratified;
  FiberSurfaceLobe surface_lobe = FiberSurfaceLobe::kSampled;
};

// The defaults for a spec and route: FiberTableBakeOptions{}, less the variance reductions that do
// not apply (next-event estimation and surface samples need the smooth boundary, next-event
// estimation and the stratified entry the direct route), which a bake would refuse. Front ends
// and the bake cache start from these.
FiberTableBakeOptions fiber_bake_defaults(const FiberSpec& spec,
                                          FiberBakeRoute route = FiberBakeRoute::kDirect);

struct FiberBandSummary {
  int band = 0;
  double wavelength_nm = 0;
  double mu_s_per_um = 0, mu_a_per_um = 0, g = 0;
  double surface_fraction = 0;  // reflected by the surface lobe (of the light hitting the fiber)
  double exit_fraction = 0;     // everything that leaves: surface + volume
  double absorbed_fraction = 0;
  double lost_fraction = 0;
  double roulette_net = 0;             // Russian roulette's net removal (mean zero)
  double surface_sampling_excess = 0;  // sampled minus tabulated surface albedo (mean zero)
  double expected_exit_excess = 0;     // next-event estimated minus traced exits (mean zero)
  double energy_balance = 0;  // exit + absorbed + roulette + lost - both excesses: 1 to rounding
  // The factor the table was scaled by so that its energy is the walk's own exits, (exit_fraction
  // - expected_exit_excess) / exit_fraction; 1 for plain exits (docs/fiber-bsdf.md, "The
  // energy of a next-event table").
  double energy_scale = 1;
  double energy_table = 0;  // table energy sum / pi: walk_exit_fraction() (white furnace)
  // What the photons' own walks sent out (surface + volume): exit_fraction for plain exits, the
  // exits that next-event estimation stands for otherwise. A lossless fiber's is 1 less what was
  // lost, plus the surface lobe's sampling excess.
  double walk_exit_fraction() const { return exit_fraction - expected_exit_excess; }
  uint64_t photons = 0;
  uint64_t scattering_events = 0;
};

// How far above 1 a fiber table's total albedo may read and still be a fiber's: its tabulation
// error. The classic fiber at reflectance 1 (lossless, total albedo 1 by construction) tabulates
// to at most this above 1 (test_fabric_raytrace.cpp), a lossless white cotton to 1.0004.
inline constexpr double kFiberAlbedoAllowance = 0.01;

struct FiberTableBakeResult {
  TabulatedBsdfTable table;
  std::vector<FiberBandSummary> bands;
  uint64_t photons = 0;
  uint64_t scattering_events = 0;
  double rgb_negative_clipped = 0;  // largest negative RGB value set to 0 (out of sRGB gamut)
  bool cancelled = false;           // the table then holds the passes finished (metadata "photons")
};

// The most memory bake_fiber_table holds at once, bytes: per band a running sum and the cell
// averages over all (cells x cells) direction pairs, as doubles, and the finished table (about
// 2.3 GB at R = 32 in RGB). A front end compares it with its budget before baking.
double fiber_table_bake_bytes(const FiberTableBakeOptions& options);
// A lower bound on the CPU time of a photon, seconds: a fiber without particles (no scattering
// events) took 0.41x the time per photon of red-cotton here, whose full bake PERFORMANCE.md gives
// as 1.2 us per photon per core; so 0.5 us. Denser media take longer.
inline constexpr double kMinSecondsPerPhoton = 0.5e-6;
// The same bound for a bake's options: with next-event estimation and at least four surface
// samples (the defaults), the same particle-free fiber took 4.3x the CPU per photon of plain exits
// with one sample (2.97 against 0.69 us, 2026-12-04, docs/PERFORMANCE.md), so 2.1 us; other
// options cost at least what plain exits do.
inline constexpr double kMinSecondsPerNextEventPhoton = 2.1e-6;
double fiber_bake_min_seconds_per_photon(const FiberTableBakeOptions& options);

FiberTableBakeResult bake_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& options,
                                      const ProgressCallback& progress = no_progress());

// The pieces of bake_fiber_table, for bakes split over processes (shards of bands) or resumed
// from a checkpoint. A band's running sums after some passes: continuing from them gives the same
// bits as a bake that never stopped, and the table depends on nothing else.
struct FiberBandState {
  double mu_s_per_um = 0, mu_a_per_um = 0, g = 0;  // the medium's band (for the summary)
  std::vector<double> weighted_sum;  // photon-weighted sum over passes of the cell sums
  double surface = 0, exit = 0, absorbed = 0, roulette = 0, lost = 0, excess = 0, energy = 0;
  double exit_excess = 0;  // expected_exit_excess (next-event estimation only)
  uint64_t photons = 0, events = 0;
  uint64_t passes_done = 0;
};

struct FiberBandWork {
  int first_band = 0, last_band = kNumBands;  // the bands to trace: [first, last)
  // Where to continue from: one state per band of the range (empty: from the start).
  std::vector<FiberBandState> start;
  // Called after every pass finished by all bands of the range (a checkpoint).
  std::function<void(const std::vector<FiberBandState>&)> on_pass;
};

struct FiberBandsResult {
  std::vector<FiberBandState> bands;  // one per band of the range
  uint64_t passes = 0;                // passes of a finished bake (options.passes, clamped)
  bool cancelled = false;
};

// Photon transport for a range of bands over every pass (Mie medium first: Ctrl-C is honoured
// there too, as a weft::Error "cancelled" when nothing was traced yet).
FiberBandsResult trace_fiber_bands(const FiberSpec& spec, const FiberTableBakeOptions& options,
                                   const FiberBandWork& work,
                                   const ProgressCallback& progress = no_progress());

// The factor a band's table is scaled by: the walks' own exits over the tallied ones, 1 with
// plain exits. Next-event estimation tallies expected exits, whose sum scatters about the walks'
// own (mean zero, noise 1/sqrt(N)), so a lossless fiber's table would land above a total albedo
// of 1 as often as below; scaled, it has the energy a plain bake would have, its books exact, for
// a ratio estimator's bias of order 1/N, far below the cells' noise (docs/fiber-bsdf.md, "The
// energy of a next-event table"). Plain tables keep their bits. With the analytic surface lobe
// the sums hold the volume's exits alone, and so does the ratio.
double fiber_walk_energy_scale(const FiberBandState& band,
                               FiberSurfaceLobe lobe = FiberSurfaceLobe::kSampled);

// A band's cell averages (the table's values for that band) from its running sums over photons
// > 0, each sum times 'scale' (fiber_walk_energy_scale), mirror-folded if asked.
std::vector<double> fiber_band_averages(const FiberBandState& band, int resolution,
                                        bool mirror_fold, double scale);

// The table and summary from the states of all kNumBands bands.
FiberTableBakeResult finish_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& options,
                                        const std::vector<FiberBandState>& bands, bool cancelled);

}  // namespace weft
