#pragma once
// The ray-traced fabric BSDF, the reference the summations (fabric/fabric_summation.h)
// are measured against: a virtual gonioreflectometer on one repeat of a woven sample with periodic
// boundaries. For every incident bin a parallel beam (directions spread over the bin) falls on the
// tile from above or from below; each light particle is followed through the sample with the fiber
// table at every hit until it leaves the cloth's slab, and its exit direction is binned: the
// exits of all particles, reflected and transmitted, are the fabric table (cosine-weighted cell
// averages, materials/bsdf_table.h).
//
// The fiber table is the BSDF of a whole fiber (docs/fiber-bsdf.md): the radiance leaving a point
// B for light entering anywhere on the fiber. A renderer shades a fiber point with it and lets
// light from behind B pass through B's own fiber. Traced forwards, a particle whose line meets a
// fiber therefore lights both points where that line crosses the fiber's surface: where it enters
// (B') and where it would leave (B''); it is re-emitted from one of them (chosen in proportion to
// the table's albedo there, weighted to stay unbiased) into a direction drawn from the table's cell
// averages at that point, both for the channel the particle follows (ChannelSampling). The cloth is
// periodic: the geometry is the repeat and its eight neighbours, and a particle crossing a side of
// the repeat re-enters through the opposite side.
//
// At yarn detail the tubes take the fibers' part: light a tube sends into itself leaves it through
// its far side (as light leaves a fiber through the fiber), the table's frame at a tube point is
// its facet's (normal and the yarn's tangent), so that the transport is reciprocal, and a tube
// crossing returns what a round fiber returns for light along its line, averaged over where lines
// cross the fiber (line_albedo.h): the table conserves energy only so averaged.
//
// Frames: the woven sample is in glTF's frame (y up, warp along x, weft along z); the fabric table
// is in the cloth frame x = warp, z = the cloth's normal (+y), y = z x x (= -z in glTF).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_table.h"
#include "weft/scenes/weave.h"

namespace weft {

// How a particle's path is drawn when the fiber table's channels differ. spectral_mis: each
// particle follows one hero channel, chosen uniformly, and every channel is weighted by the balance
// heuristic over the channels' path densities (one-sample MIS over channels, as Wilkie et al. 2014
// do over wavelengths); Russian roulette on the largest channel weight. Every channel's paths are
// then drawn about as often as it needs, so the channels' relative noises are alike. mean: the
// channels' mean steers the path and the roulette (the estimator before spectral MIS, kept to
// compare with: in a strongly coloured fabric the dominant channel's weights grow along multiply
// scattered paths and it is far noisier than the others).
enum class ChannelSampling { spectral_mis, mean };
// The names the table's metadata and a part's job use.
inline constexpr NameTable<ChannelSampling, 2> kChannelSamplingNames{{
    {ChannelSampling::spectral_mis, "hero", "hero channel, MIS over channels"},
    {ChannelSampling::mean, "mean", "the channels' mean"},
}};

// The light that passes straight through the gaps between the fibers (meeting none) leaves along
// its launch direction, into one cell per incident bin. exact: its expectation is computed
// (straight_through.h: randomized quasi-Monte Carlo over the launch's law, with its variance) and
// the particles book only what meets a fiber; sampled: the particles book it too (the estimator
// before the option, bit for bit). Both are unbiased; exact removes that cell's hit-or-miss noise.
enum class StraightThrough { exact, sampled };
// The names the command line and the table's metadata use, in the command line's order.
inline constexpr NameTable<StraightThrough, 2> kStraightThroughNames{{
    {StraightThrough::exact, "exact", "computed"},
    {StraightThrough::sampled, "sampled", "booked by the particles"},
}};

// Which light the sheen (FabricRaytraceOptions::sheen_h_resolution) books: first-surface, the
// light the first fiber a particle meets reflects off its surface lobe and that leaves at once
// (the cells keep the rest); reflected, every exit on the light's side whose half vector lies in
// the window, whatever its path: a finer grid about the mirror, where a satin's peak also holds
// light that crossed fibers and light that the first fiber's lobe did not reflect, which an
// R 8 light bin blurs (docs/fabric-bsdf.md, "Sharp sheen").
enum class SheenLight { first_surface, reflected };
inline constexpr NameTable<SheenLight, 2> kSheenLightNames{{
    {SheenLight::first_surface, "first-surface", "the first fiber's surface reflection"},
    {SheenLight::reflected, "reflected", "every reflected exit in the window"},
}};

// The estimator's revision, raised whenever a change alters its results for the same options: it
// is part of a sharded or resumed run's identity (parts of another revision are refused, not
// merged) and of the table's metadata. 2: the scene passes rays through fibers they are inside
// (a fiber's continuation across the repeat's sides), before which particles leaving a fiber near
// the side were passed through that cap by a rule of the estimator's own and scattered by any
// other fiber met from inside. 3: a yarn tube's crossing returns the fiber table's line albedo
// (what a round fiber returns, averaged over where lines cross it), before which it returned
// A' + A'' at its facets: 1.2 of the light at normal incidence for a nearly lossless white-cotton
// fiber. Fiber-detail results are unchanged. The straight-through option (StraightThrough)
// changed the default's results without a new revision: the table's metadata and a part's job
// name it where it is exact, so a part or table of revision 3 without it is the sampled
// estimator's, which the option still gives bit for bit. 4: a spectral table's paths are drawn
// by three strategies, each a third of its bands (FiberSampler), before which each band had its
// own; the results are the same in distribution, RGB tables' bit for bit.
inline constexpr int kFabricRaytraceRevision = 4;

// The most next-event draws per scattering and particles per launch block
// (FabricRaytraceOptions::next_event_rays, launch_lattice).
inline constexpr int kMaxNextEventRays = 64, kMaxLaunchLattice = 1024;

// A narrow light and the exits about its plane of incidence: a reference for a mirror peak finer
// than any table's cells (weft bench sheen, bench/sheen_bench.h). Every particle comes from a
// direction within half_angle_deg of (theta_deg, azimuth_deg) (towards the light, cloth frame;
// uniform over that cone's solid angle; 0: a collimated beam) and enters anywhere on the repeat;
// the run traces only the incident bin holding that direction, whose row of the table is then this
// light's. Besides the table, the reflected exits within band_deg across the plane of incidence
// are booked by their angle in it in bins of bin_deg (FabricRaytraceResult::plane_f). A table's
// cells average a peak over their 2 pi / R^2 sr and a light bin over its light; this does neither.
struct NarrowLight {
  double theta_deg = 45, azimuth_deg = 0, half_angle_deg = 0;
  double band_deg = 4, bin_deg = 0.5;
  // The angles in the plane that plane_f covers: [-kMaxPlaneDeg, kMaxPlaneDeg] (f grows as
  // 1 / cos^2 there, and a bin reaching 90 degrees would have an unbounded variance).
  static constexpr double kMaxPlaneDeg = 89;
  // The ranges its fields are checked against (FabricRaytraceOptions::validate, and every reader
  // of them).
  static constexpr double kMaxHalfAngleDeg = 10, kMinBandDeg = 0.01, kMaxBandDeg = 60;
  static constexpr double kMinBinDeg = 0.05, kMaxBinDeg = 10;
  int plane_bins() const;  // kMaxPlaneDeg * 2 / bin_deg, rounded down
  // The angle in the plane at the centre of plane bin k, degrees (negative on the mirror's side).
  double plane_angle_deg(int k) const { return -kMaxPlaneDeg + (k + 0.5) * bin_deg; }
};

struct FabricRaytraceOptions {
  int resolution = 8;                  // of the fabric table (DirectionGrid R)
  uint64_t particles_per_bin = 20000;  // per incident bin
  uint64_t seed = 1;
  int threads = 0;                   // 0 = all cores; results do not depend on it
  int max_scatterings = 1000;        // beyond it a particle's weight is booked as lost
  double roulette_threshold = 0.05;  // Russian roulette below this weight (see ChannelSampling)
  // A particle whose largest channel weight exceeds this splits into copies (not with mean).
  double split_threshold = 1.0;
  // The most copies one particle's splits make in all. Splitting is optional (any count keeps the
  // estimate unbiased), so the cap changes only the noise; it bounds a particle's work where
  // weights grow at every event (a table whose line albedo stays above 1 makes copies grow
  // geometrically). A particle at the cap keeps its weight, so a low cap leaves a heavy tail:
  // at 64, 0.013 % of the particles carried half of red's largest contributions on red cotton
  // (docs/PERFORMANCE.md); at 1024 none reached it, at the same cost.
  int max_copies_per_particle = 1024;
  ChannelSampling channel_sampling = ChannelSampling::spectral_mis;
  StraightThrough straight_through = StraightThrough::exact;
  // The next-event estimate of the exits (0: off, the particles' own exits are binned). At every
  // scattering, this many draws of the step the particle is about to take (the same point, cell
  // and direction distribution and the same weights as its own) are each followed along their
  // line, without scattering, out of the slab or to the surface that stops them; each that leaves
  // books its weights over the count into its cell. The particle's own exit after a scattering is
  // then not binned (its expectation is what the draws book); an exit before any scattering
  // (light passing straight through) is, as without. Every scattering, not only the last, adds to
  // the table: unbiased, each draw having the law of the exit it replaces.
  int next_event_rays = 0;
  // Particles launched in blocks of this many (1: each on its own): a block's particles share one
  // direction of the bin and enter at the points of a lattice over the repeat through one entry
  // point (raytrace::lattice_point), both drawn at random per block, so that each particle is
  // still launched as without. On a dense cloth the light that passes straight through the gaps
  // between the fibers goes to one cell per incident bin, whose hits and misses were most of the
  // table's noise (docs/PERFORMANCE.md); a block's lines cover the gaps evenly. A block's exits are
  // summed per cell before the variance is taken (the blocks are the independent samples), so the
  // stated noise stays honest.
  int launch_lattice = 1;
  // Trace only incident bins [first_bin, first_bin + bin_count) (0: all), for a table split over
  // processes: their rows have the bits of a whole run's, the other rows are zero.
  int first_bin = 0, bin_count = 0;
  // Optional: draw the paths from this fiber table (same resolution and channels) and weight each
  // step by f / f_proposal of the fiber table traced (likelihood-ratio reweighting). Every choice
  // (B' or B'', exit cell and direction, roulette, splitting) then depends on the proposal alone,
  // so at a fixed seed the particles keep their paths when the fiber table changes and the result
  // is a smooth function of it: weft verify --fit's inner model (docs/verify.md). Unbiased where
  // the proposal is nonzero wherever the table is; the noise grows as the two tables differ. Null:
  // the fiber table itself (the default estimator, bit for bit). At a fixed seed the paths can be
  // recorded once and re-weighted for other tables (recorded_paths.h).
  const TabulatedBsdfTable* proposal = nullptr;
  // The weave tally (weave_tally.h; 0: off): the exits binned also by where their line crosses
  // the cloth's mid-plane, in weave_positions_u x weave_positions_v cells of the repeat (u along
  // the warp), at a coarse DirectionGrid of weave_resolution (at most the table's): the
  // result's weave table. It draws no random number, so the table keeps its bits either way.
  int weave_positions_u = 0, weave_positions_v = 0;
  int weave_resolution = 4;
  // The sheen booked apart (0: off): the light that the first fiber a particle meets reflects off
  // its surface lobe and that leaves at once, binned per incident bin by its half vector on
  // DirectionGrid{sheen_h_resolution}'s window of sheen_window bins a side about the pole: the
  // table's sheen (materials/half_vector_lobe.h), which holds a mirror peak narrower than the
  // table's bins. Needs fiber detail and a fiber table with an analytic surface lobe (weft bake
  // fiber --surface-lobe analytic), traced whole (not in parts). Draws no random number: the
  // cells plus the sheen's cell averages estimate what the cells alone do.
  int sheen_h_resolution = 0;
  int sheen_window = 16;
  // The sheen's light bins (HalfVectorLobe::light_resolution): 0 the table's, or 2 or 4 times its
  // resolution, the particles of each table bin launched in turn from its nested finer bins.
  // Finer light bins hold a satin's mirror peak where the light's own bin would blur it.
  int sheen_light_resolution = 0;
  SheenLight sheen_light = SheenLight::first_surface;
  // The narrow light in place of the bins' beams (none: every bin's beam). first_bin and bin_count
  // stay 0 (its bin is traced), the straight-through light is sampled (its exact part is a bin's
  // beam's), and it takes no sheen, weave tally or recording.
  std::optional<NarrowLight> narrow_light;

  void validate() const;  // weft::Error naming the field
};

// What one incident bin's particles booked: the totals of FabricRaytraceResult are sums of these
// in bin order (fabric_raytrace_totals), so a table traced in pieces (first_bin, bin_count) and
// put together has the whole run's books and noise bit for bit.
struct FabricBinBooks {
  double launched = 0, exited = 0, absorbed = 0, lost = 0, roulette_net = 0;  // power
  uint64_t particles = 0, scatterings = 0, wraps = 0, splits = 0, roulette_kills = 0;
  uint64_t inside_hits = 0, tube_passes = 0;
  // Per channel, over the bin's row of the table: sum of se^2 D_i D_o and of f^2 D_i D_o (the
  // relative noise's numerator and denominator, D the cosine-weighted areas).
  std::vector<double> noise2, signal2;
  // With the weave tally: per (position, coarse outgoing bin, channel) this bin's part of the
  // booked values B (weave_totals), and per channel its part of their noise's numerator.
  std::vector<double> weave_values, weave_noise2;
  void add(const FabricBinBooks& other);  // the power and counts (not noise2, signal2, weave)
};

struct FabricRaytraceResult {
  TabulatedBsdfTable table;  // kind "fabric", the fiber table's channels
  // Energy books, as fractions of the power that fell on the cloth (mean over channels): exited +
  // absorbed + lost + roulette_net = 1 to rounding. absorbed is what the fibers' tables keep
  // (1 - A' - A'' per scattering, A the albedo of the table at the two crossing points).
  // exited is the power of the particles that left the slab; with the next-event estimate the
  // table books the expectation of those exits instead, so the table's albedo agrees with exited
  // only within the noise.
  double exited = 0, absorbed = 0, lost = 0, roulette_net = 0;
  uint64_t particles = 0, scatterings = 0, wraps = 0;
  // Copies made by splitting, and particles (or copies) ended by Russian roulette, in all and
  // per incident bin (what a bin's particles did depends only on (seed, bin), like its row).
  uint64_t splits = 0, roulette_kills = 0;
  std::vector<uint64_t> splits_per_bin, roulette_kills_per_bin;
  // Fiber detail: hits on a fiber that the particle's line only grazes from inside (taken alone,
  // without their B''); the scene passes a ray through any fiber it is inside (RenderScene), so
  // none are expected but at ties of rounding.
  uint64_t inside_hits = 0;
  // Yarn detail: particles that a tube sent into itself and that left it through its far side.
  uint64_t tube_passes = 0;
  // Standard error of the table relative to its values, weighted like weft compare's rel_rms
  // (by D_i D_o, channels summed): what two independent runs would differ by, over sqrt(2).
  double relative_noise = 0;
  std::vector<double> relative_noise_per_channel;  // the same, channel by channel
  std::vector<float> standard_error;               // per value of the table (cell pair and channel)
  std::vector<FabricBinBooks> bin_books;  // per incident bin (zero outside the bins traced)
  // With the weave tally (FabricRaytraceOptions::weave_positions_u): the weave table, m = B / the
  // mean of B over the positions (1 where that mean is 0), B per position cell p what the exits
  // through p booked as a cosine-weighted coarse cell average, scaled to the cell's share of the
  // repeat (the local BSDF at p); weave_mean that mean per [coarse wi][coarse wo][channel], the
  // fabric table's coarse average to rounding (coarse_table_average); and the relative noise of B,
  // weighted like the table's (D_i D_o over the coarse cells, positions and channels summed).
  WeaveTable weave;
  std::vector<double> weave_mean;
  double weave_relative_noise = 0;
  // With a narrow light (FabricRaytraceOptions::narrow_light): per bin k of the angle in its plane
  // of incidence, theta' in [-89 + k bin_deg, -89 + (k + 1) bin_deg) degrees (wo . u = sin theta',
  // u the plane's horizontal towards the light: a view at v degrees on the mirror's side is
  // theta' = -v), and channel, the mean of f over the bin's theta' and the band's angle across the
  // plane (phi', wo = u sin theta' + cos theta' (n cos phi' + v sin phi'), dw = cos theta' dtheta'
  // dphi'), and its standard error.
  std::vector<double> plane_f, plane_f_se;
  // The progress callback stopped the trace: the rest of the result is not filled in.
  bool cancelled = false;
};

// The totals above (energy books, counts, relative noise) from bin_books, summed in bin order.
void fabric_raytrace_totals(FabricRaytraceResult& result);

// A lower bound on the CPU time of one particle of the ray trace, seconds: PERFORMANCE.md gives
// about 0.8 M particles/s at fiber detail and 1.2 M/s on yarn tubes on 2 threads (1.7 us per
// particle per core on tubes); a particle that meets no fiber is cheaper, so 0.25 us. A front end
// estimates a ray trace's time with it before starting.
inline constexpr double kMinSecondsPerFabricParticle = 0.25e-6;

// The peak memory, bytes, of the scene the ray trace flies its particles through (and that
// visible_fiber_tangents, for summation-visible, looks at) on a sample of this size, from the
// sample's counts alone, before anything is built: the sample, the scene description's copy of
// it (yarn tubes once, instanced at the eight neighbours; fibers copied nine times) and Embree's
// buffers and acceleration structures, at per-primitive sizes measured with peak RSS on the
// bundled samples (docs/PERFORMANCE.md). A front end refuses a run over its memory budget with it.
double fabric_scene_bytes(const WovenSampleSize& size);

// The CPU time, seconds, that a woven sample of this size costs the work done on it beyond what its
// particles and camera samples cost on a small sample, from the sample's counts alone, at rates
// measured on the bundled drafts at fiber detail (raytrace_books.cpp; yarn tubes are not counted):
// making the sample (once), building the scene of the tiled sample (once per ray trace or render),
// and every ray's slower way through a larger scene, as a factor on a particle's or camera
// sample's time (1 on a small sample).
struct FabricSceneSeconds {
  double make = 0, build = 0;
  double per_ray_factor = 1;
};
FabricSceneSeconds fabric_scene_seconds(const WovenSampleSize& size);

// The fiber directions seen at the cloth's surface, for the summations: the unit tangents (cloth
// frame) at the first hits of a rays_per_side x rays_per_side grid of rays along the normal over
// one repeat, from above (views on the cloth's face) or from below. Each stands for an equal share
// of the cloth's area.
std::vector<Vec3> visible_fiber_tangents(const WovenSample& sample, bool from_above,
                                         int rays_per_side = 64);
// Both sides' at once, from one scene, as summation-visible takes them: the scene's copies and
// build poll 'progress', and so do the rays, a row at a time; nothing when it said stop. The same
// tangents as the call above on either side.
struct VisibleFiberTangents {
  std::vector<Vec3> top, bottom;
};
std::optional<VisibleFiberTangents> visible_fiber_tangents(const WovenSample& sample,
                                                           const ProgressCallback& progress,
                                                           int rays_per_side = 64);

FabricRaytraceResult raytrace_fabric_table(const WovenSample& sample,
                                           const TabulatedBsdfTable& fiber,
                                           const FabricRaytraceOptions& options,
                                           const ProgressCallback& progress = no_progress());

// One fiber table per yarn: a two-colour draft's warp and weft (docs/fabric-bsdf.md, "Per-yarn
// fibers"). A scattering on a fiber (or yarn tube) draws from and weighs with the table of its
// yarn; the line albedos of the yarn tubes and the paths' sampling are per table. tables[k] is
// table k (names[k] names it in errors and in the fabric table's metadata); table_of_yarn[y] the
// table of yarn y of the sample's fibers (FiberCurves::curve_yarn's index) and table_of_mesh[m]
// that of mesh m (yarn detail: "warp" and "weft"); either empty where the sample has none. All
// tables share resolution and channels. Tables with equal checksums are one table: a map onto one
// table traces bit for bit as the single-table call.
struct FiberTables {
  std::vector<const TabulatedBsdfTable*> tables;
  std::vector<std::string> names;
  std::vector<int> table_of_yarn, table_of_mesh;
};
// The most tables one ray trace takes (a draft's distinct thread colours are fewer).
inline constexpr int kMaxFiberTables = 64;
// The sample's warp yarns (material "warp", the "warp" mesh) take 'warp', the others 'weft'.
FiberTables fiber_tables_by_direction(const WovenSample& sample, const TabulatedBsdfTable& warp,
                                      const TabulatedBsdfTable& weft);
// One table per distinct thread colour of the sample (WovenSample::yarn_rgb, a WIF draft's), in the
// order they first appear among its yarns (warps, then wefts): the map, its tables left null for
// the caller, and 'colours' the colours in table order. At yarn detail each direction's tubes are
// one mesh: weft::Error naming 'field' when a direction's yarns differ in colour, and when the
// sample has no colours.
FiberTables fiber_tables_by_colour(const WovenSample& sample,
                                   std::vector<std::array<double, 3>>& colours,
                                   const std::string& field);
// weft::Error naming the table ("fiber tables[k] (name)") or the map when the tables differ in
// resolution or channels, are not fiber tables, or the maps do not fit the sample.
void validate_fiber_tables(const FiberTables& tables, const WovenSample& sample);
// How errors name table k: "fiber tables[k] (name)".
std::string fiber_table_field(const FiberTables& tables, size_t k);
// The same map onto the distinct tables (equal checksums are one; the first one's name is kept).
FiberTables distinct_fiber_tables(const FiberTables& tables);
// A proposal (FabricRaytraceOptions::proposal) is refused with more than one distinct table.
FabricRaytraceResult raytrace_fabric_table(const WovenSample& sample, const FiberTables& fibers,
                                           const FabricRaytraceOptions& options,
                                           const ProgressCallback& progress = no_progress());

}  // namespace weft
