#pragma once
// The steps of a light particle's life in the fiber-level ray trace (fabric_raytrace.h), a
// function each so that each can be tested alone:
//   launch      a particle of an incident bin enters the slab through the face it faces;
//   flight      along its line to the next surface, out of the slab, or through a side of the
//               repeat, where it re-enters through the opposite side (the periodic wrap);
//   crossings   a line that meets a fiber lights B' and B'', where it enters and would leave it;
//   scattering  the hero strategy picks B' or B'' and an exit direction from the fiber table, and
//               the path's weights become f over the strategies' mean probability (MIS); a yarn
//               tube's crossing returns the line albedo of the fiber it stands for;
//   tally       a particle leaving the slab adds its weights to its (incident, outgoing) cell
//               (with the next-event estimate, draws of its exit followed out of the slab:
//               escape_direction; particles launched in blocks on a lattice: lattice_point);
//   roulette and splitting  keep the weights in a window (below: roulette; above: copies).
// Frames: world is the woven sample's (glTF, y up, metres), cloth the fabric table's (z = +y).
// The steps that draw random numbers draw them in a fixed order from the particle's task stream:
// the table's bits for a seed depend on it, so it is part of each step's contract.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/rng.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fiber_sampler.h"
#include "weft/fabric/line_albedo.h"
#include "weft/fabric/recorded_paths.h"
#include "weft/fabric/weave_tally.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

namespace weft::raytrace {

inline Vec3 cloth_to_world(const Vec3& c) {
  return {c.x, c.z, -c.y};
}
inline Vec3 world_to_cloth(const Vec3& w) {
  return {w.x, -w.z, w.y};
}

// One repeat of the sample and its slab (world frame, metres): x in [x0, x0 + px], z in
// [z0, z0 + pz], y in [y0, y1].
struct RepeatSlab {
  double x0 = 0, z0 = 0, px = 0, pz = 0, y0 = 0, y1 = 0;
};
// The sample's repeat, centred on the origin (zero sizes where the sample has none).
RepeatSlab repeat_slab_of(const WovenSample& sample);

// A particle between two events; a copy made by splitting waits as one.
struct Particle {
  Vec3 p, d;
  int events = 0;             // scatterings, wraps and tube passes so far
  int64_t ignore = kNoFiber;  // the fiber last left (fiber detail)
  bool in_tube = false;       // sent into the yarn tube it left (yarn detail)
  std::vector<double> w;      // channel weights
  std::vector<double> pdf;    // per strategy, the path's density relative to their mean
  std::vector<double> wp;     // the weights under the proposal (with one; else empty)
  bool scattered = false;     // by a fiber since its launch
  // With the sheen booked apart (FabricRaytraceOptions::sheen_h_resolution): per channel the
  // share of w that its first scattering reflected off the fiber's surface lobe, while that is
  // its only scattering; empty otherwise.
  std::vector<double> sheen;
};

// The mean of the channel weights (the power the books count).
double mean_weight(std::span<const double> w);

// --- launch
// The light of incident bin 'bin': a direction of the bin (uniform in solid angle), entering the
// slab through the face it faces at a uniform point of the repeat; its flux per unit area is
// proportional to w0 = |cos theta_i|. With strata > 1 the direction is drawn from sub-square
// 'stratum' (row-major) of the bin's strata x strata in the chart: the finer grid's bin nested
// there (a sheen's light bins, materials/half_vector_lobe.h).
struct Launch {
  Vec3 p, d;
  double w0 = 0;
};
Launch launch(const DirectionGrid& grid, const RepeatSlab& slab, int bin, Rng& rng, int strata = 1,
              int stratum = 0);

// Point m of the rank-1 lattice of 'count' points over the repeat that contains p (its point 0):
// the fractions (m / count, m g / count) of the periods added to p's, modulo the periods, g the
// integer nearest count over the golden ratio (a Fibonacci lattice when count is a Fibonacci
// number; Sloan & Joe, Lattice Methods for Multiple Integration, 1994). Each point is uniform over
// the repeat when p is, and together they cover it evenly.
Vec3 lattice_point(const RepeatSlab& slab, const Vec3& p, int m, int count);

// The sampling strategies a path is drawn and weighted with (FiberSampler strategy indices). With
// spectral MIS one per channel group (FiberSampler::groups: a channel of an RGB table, a few
// adjacent bands of a spectral one), and the particle follows its hero, drawn uniformly; else one,
// the channels' mean.
struct Strategies {
  bool mis = false;
  int count = 1;
  int hero = 0;  // the strategy the path follows
  int mean = 0;  // the channels' mean: the group count
  int index(int j) const { return mis ? j : mean; }
  int hero_slot() const { return mis ? hero : 0; }  // the j of the hero
};
Strategies draw_strategies(bool mis, int groups, Rng& rng);

// The particle as it is launched: weights w0 in every channel (and under the proposal, when
// 'proposal'), path densities 1.
Particle launched_particle(const Launch& l, int channels, const Strategies& st, bool proposal);

// --- flight and the periodic wrap
// The scene the particles fly through: the repeat and its eight neighbours (weave.h
// tiled_woven_description with one copy on each side; yarn tubes instanced, so the neighbours
// take no memory of their own), geometry only. weft::Error when the
// sample has neither fibers nor yarn tubes. The yarn tubes are the sample's own, not copies: the
// description, and any scene built from it, must not outlive 'sample'.
SceneDescription tiled_geometry(const WovenSample& sample);
// The same, the fibers' copies polling 'progress' (tiled_woven_description); nothing when it said
// stop.
std::optional<SceneDescription> tiled_geometry(const WovenSample& sample,
                                               const ProgressCallback& progress);
// Along the line p + t d: the distance to the first side of the repeat it crosses (side 0: -x,
// 1: +x, 2: -z, 3: +z; -1 and infinity for none) and to the slab's face ahead (infinity if none).
struct Boundaries {
  double t_side = 0;
  int side = -1;
  double t_slab = 0;
};
Boundaries boundaries_ahead(const RepeatSlab& slab, const Vec3& p, const Vec3& d);

// The point where the line leaves the repeat through 'side', moved by one period: it re-enters
// through the opposite side.
Vec3 wrap_through_side(const RepeatSlab& slab, const Vec3& p, const Vec3& d, double t_side,
                       int side);

// The tiled scene is the repeat and its eight neighbours: copy (i, k), shifted by (i Px, k Pz)
// with i, k in {-1, 0, 1}, is copy number 3 (i + 1) + (k + 1), and fiber c of the sample in copy
// q is fiber id q * curves + c.
int copy_index(int i, int k);
// The fiber a particle ignores after it moved by one period through 'side' (re-entering through
// the opposite side): the same fiber in the copy that now lies where it was, or none when that
// copy is not part of the tiling.
int64_t fiber_after_wrap(int64_t fiber, int side, int64_t curves);

// What a particle's flight along its line ends at. 'hit': a surface (*hit); 'left_slab': a face of
// the slab, with nothing on the way; 'wrapped': a side of the repeat, and the particle now
// re-enters through the opposite side (p and ignore moved, events not counted).
enum class Flight { hit, left_slab, wrapped };
Flight fly(const RenderScene& scene, const RepeatSlab& slab, int64_t curves, Particle& s,
           SurfaceHit* hit);
// Light that a yarn tube sent into itself leaves it through its far side, as light leaves a fiber
// through the fiber itself: the table already holds the whole yarn's part (taking that exit as a
// new crossing scattered it twice, and only when it left into the tube, which made the yarn-detail
// tables non-reciprocal). True, and the particle moved past h, when h is that far side; either
// way the particle is no longer in its tube.
bool passes_own_tube(const SurfaceHit& h, Particle& s);
// Where a particle just sent out of a fiber goes if nothing stops it: its line (wrapped through
// the repeat's sides, and through its own yarn tube) is followed to the first surface it meets or
// out of the slab; the direction it leaves the slab along, or none when a surface is met first
// (or after max_events wraps and passes). The next-event estimate's visibility test: no
// scattering and no random draw.
std::optional<Vec3> escape_direction(const RenderScene& scene, const RepeatSlab& slab,
                                     int64_t curves, Particle& s, int max_events);

// --- crossings
// Where a particle's line meets a fiber: the point, its local frame (x = axis, z = outward), the
// direction the light came from in it and that direction's bin of the fiber table.
struct FiberPoint {
  SurfaceHit hit;
  Vec3 wi_local;
  int bin = 0;
};
// B' and B'': the line along d meets a fiber (or yarn tube) at h and would leave it at the other
// point; count 1 when h stands alone (a graze, or a hit from inside, B' behind it not found).
// On a yarn tube the frame is the facet's (its normal and the yarn's tangent).
struct Crossings {
  std::array<FiberPoint, 2> pts;
  int count = 0;
};
Crossings crossings_of(const RenderScene& scene, const SurfaceHit& h, const Vec3& d,
                       const DirectionGrid& fiber_grid);

// --- scattering
// Per strategy slot j the sum S_j of its albedos at the crossings.
void albedo_sums(const FiberSampler& fs, const Strategies& st, const Crossings& x,
                 std::span<double> s_sum);
// The hero's choice: B' or B'' (point) in proportion to its albedo there, an exit cell from its row
// there and a direction in the cell (fiber frame); with probability f_h D_o / S_h. None (and no
// draw) when the hero's S is 0: the fiber absorbs all of its light.
// With the sampler's exact lobe (FiberSampler::lobe) the point is chosen in proportion to its
// albedo and its lobe's, and the lobe with probability its share there: the exit is then the
// lobe's own draw (exit_bin its cell), or none when that draw leaves the lit side (the lobe's
// density is what the weights divide by, so the estimate stays unbiased).
struct ScatterDraw {
  int point = 0;
  int exit_bin = 0;
  Vec3 wo_local;
};
std::optional<ScatterDraw> draw_scatter(const FiberSampler& fs, const Strategies& st,
                                        const Crossings& x, std::span<const double> s_sum,
                                        Rng& rng);
// The path's weights after scattering from light bin 'bin' into cell 'exit_bin': times f_c over
// the strategies' mean probability of the step (the proposal's weights times its own f), the
// densities kept relative to their mean. Returns the power the step absorbed (channels' mean);
// the mean probability the weights were divided by into *mean_pdf_out where given
// (recorded_paths.h).
double weigh_scatter(const FiberSampler& fs, const TabulatedBsdfTable& fiber, const Strategies& st,
                     int bin, int exit_bin, std::span<const double> s_sum, Particle& s,
                     double* mean_pdf_out = nullptr);
// The same with the sampler's exact lobe: f_c = the rest's cell value + the lobe's f_c at (wi, wo)
// of the point drawn, over the strategies' mean density of the step, (g_j |cos theta_o| + lobe
// albedo_j p_lobe) / S_j (every strategy's density now differs by more than a common factor).
// With 'lobe_share' (channels values; empty: not asked) the share of each channel's new weight
// that the lobe's f gives.
double weigh_scatter_lobe(const FiberSampler& fs, const TabulatedBsdfTable& rest,
                          const Strategies& st, const FiberPoint& pt, const ScatterDraw& draw,
                          std::span<const double> s_sum, Particle& s,
                          std::span<double> lobe_share = {});
// A yarn tube stands for a round fiber: the weights after scattering at the tube's crossing x of
// the line along d are scaled per channel by L_c / S_c, L the table's line albedo for d
// (line_albedo.h, axial cosine with the yarn's tangent at x.pts[0]) and S_c the albedos summed
// over x's points (unchanged where S_c is 0: nothing of c leaves there), so that the crossing
// returns what the fiber returns on average. The tube's facets keep choosing where and in which
// direction the light leaves, but their A' + A'' is not the fiber's: light along the normal meets
// both faces of the flattened section head-on, as only lines through a round fiber's axis do,
// where a clear fiber's A' + A'' is 2 to 3 (docs/fabric-bsdf.md). The proposal's weights (wp)
// are scaled by its own L / S. Returns the power this absorbed (channels' mean; negative where it
// adds).
double weigh_as_round_fiber(const LineAlbedo& traced, const LineAlbedo* proposal,
                            const Crossings& x, const Vec3& d, Particle& s);
// Its scaling of one weight vector: per channel times L_c(axial) / S_c, S_c the point albedos of
// 'bins' (the crossing's fiber bins) summed.
void scale_as_round_fiber(const LineAlbedo& table, double axial, std::span<const int> bins,
                          std::vector<double>& w);
// The particle leaves fiber point 'hit' along wo_local (its frame): the new line, the fiber to
// pass through, and whether it was sent into its own yarn tube.
void leave_fiber(const SurfaceHit& hit, const Vec3& wo_local, Particle& s);

// --- tally
// An exit of a particle of incident bin 'bin' leaving the slab along d (world): its cell of the
// fabric table, incident bin * bins + outgoing bin (cloth frame).
struct ExitRecord {
  uint64_t cell;
  uint32_t first;  // index of its channel weights in the tally's weight list
};
struct Tally {
  std::vector<ExitRecord> exits;
  std::vector<double> weights;  // channels per exit
  // The books of the particles by incident bin (a task may straddle two bins): kept apart so that
  // every bin's books sum alike however the bins are split over runs.
  std::vector<std::pair<int, FabricBinBooks>> books;
  WeaveExits weave;              // the weave tally's exits, when on (weave_tally.h)
  std::vector<PathOp> path_ops;  // the task's steps, when recorded (recorded_paths.h)
  FabricBinBooks& books_of(int bin);
};
uint64_t exit_cell(const DirectionGrid& grid, int bin, const Vec3& d);
// Adds the weights w to the cell; a particle's exits (those from first_exit on) are merged per
// cell, so that the per-cell variance stays that of one particle's total.
void tally_exit(Tally& tally, size_t first_exit, uint64_t cell, std::span<const double> w);

// --- Russian roulette and splitting
// The weights that decide them: the mean of w (the books), and of the deciding weights (w, or the
// proposal's wp where there is one) their mean and their largest.
struct Steering {
  double mean_w = 0, mean_p = 0, max_w = 0;
};
Steering steering_of(const Particle& s);
// Russian roulette on 'steer' below 'threshold': the particle survives with probability
// steer / threshold and its weights are divided by it. False when it dies; both books the net
// change of the power (mean_w before). The divisor of a survivor into *divided_by where given.
bool survives_roulette(double steer, double threshold, double mean_w, Particle& s,
                       FabricBinBooks& books, Rng& rng, double* divided_by = nullptr);
// The most copies one split makes (the weights are divided by the count made, so any cap is
// unbiased; it bounds the work a freak weight can cause).
inline constexpr int kMaxSplit = 16;
// How many copies (the particle included) a split of largest weight max_w makes, with 'copies_left'
// more allowed to the particle.
int split_count(double max_w, double split_threshold, int copies_left);
// Divides the weights by n and leaves n - 1 copies in 'pending'.
void split(Particle& s, int n, std::vector<Particle>& pending);

}  // namespace weft::raytrace
