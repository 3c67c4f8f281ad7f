#include "weft/fabric/fabric_raytrace.h"

#include <algorithm>
#include <deque>
#include <optional>
#include <string>

#include "raytrace_table.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/task_batch.h"
#include "weft/fabric/fiber_sampler.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/fabric/recorded_paths.h"
#include "weft/fabric/straight_through.h"
#include "weft/fabric/weave_tally.h"
#include "weft/scenes/render_scene.h"

namespace weft {

namespace raytrace {
namespace {

// What a scattering at a hit draws from and weighs with: the table of its yarn (FiberTables), the
// sampler its paths are drawn from and its yarn tubes' line albedo.
struct YarnShading {
  const FiberSampler* fs = nullptr;
  const TabulatedBsdfTable* fiber = nullptr;
  const LineAlbedo* tube = nullptr;
};

// What all the particles of a run share: the scene, the tables and the estimator's choices.
struct Tracer {
  const RenderScene& scene;
  RepeatSlab slab;
  int64_t curves = 0;               // per copy of the sample in the scene (fiber detail)
  const FiberSampler& fs;           // draws the paths: from the proposal, or the fiber table
  const TabulatedBsdfTable& fiber;  // the table traced
  const FabricRaytraceOptions& o;
  DirectionGrid grid;  // of the fabric table
  int nc = 0;          // channels
  // Spectral MIS over the channels (the particle follows a hero); roulette on the largest weight
  // and splitting (all but the estimator before, mean); paths drawn from a proposal.
  bool mis = false, window = false, proposal = false;
  // The particles traced are [first_item, last_item); particle k is of incident bin k / per_bin.
  uint64_t per_bin = 0, first_item = 0, last_item = 0;
  // Yarn detail: the line albedos of the table traced and of the proposal (weigh_as_round_fiber).
  const LineAlbedo* tube = nullptr;
  const LineAlbedo* tube_proposal = nullptr;
  // Per-yarn tables (FiberTables, two or more distinct): each table's shading, and which table a
  // fiber (per curve of the sample) or a yarn tube (per mesh) takes. Empty: every hit takes the
  // fields above.
  std::vector<YarnShading> shadings{};
  std::vector<int> table_of_curve{}, table_of_mesh{};
  const WeaveLayout* weave = nullptr;  // the weave tally, when on
  bool record = false;                 // the steps into each task's path_ops (recorded_paths.h)
  // The sheen's window when it is booked apart (its shape; FabricRaytraceOptions::
  // sheen_h_resolution): its cells follow the table's in the tally, from sheen_first_cell on.
  const HalfVectorLobe* sheen = nullptr;
  uint64_t sheen_first_cell = 0;
  // The narrow light (FabricRaytraceOptions::narrow_light), when on: its plane's exits follow the
  // table's cells in the tally, from plane_first_cell on.
  const LightPlane* plane = nullptr;
  uint64_t plane_first_cell = 0;
};

// Where particle idx of its bin is launched: its sub-square of the bin when the sheen's light bins
// are finer (HalfVectorLobe::light_factor), taken in turn by particle or by launch block, so that
// each finer bin has its known share of the particles (stratum_particles); 0 otherwise.
int launch_stratum(const Tracer& t, uint64_t idx) {
  const int m = t.sheen ? t.sheen->light_factor() : 1;
  if (m == 1) return 0;
  const uint64_t unit = idx / static_cast<uint64_t>(t.o.launch_lattice);
  return static_cast<int>(unit % static_cast<uint64_t>(m * m));
}

// A step of the particle's life into its task's record, when recording.
void record_op(const Tracer& t, Tally& tally, PathOp op) {
  if (t.record) tally.path_ops.push_back(op);
}

// The shading of the yarn the particle's line met at h: its fiber's (fiber detail, the same fiber
// in every copy of the repeat) or its tube's (yarn detail, the instanced mesh).
YarnShading shading_at(const Tracer& t, const SurfaceHit& h) {
  if (t.shadings.empty()) return {&t.fs, &t.fiber, t.tube};
  const int k = h.on_fiber() ? t.table_of_curve[static_cast<size_t>(h.fiber % t.curves)]
                             : t.table_of_mesh[h.shape];
  return t.shadings[k];
}

// A particle's life from its launch: where its exits and books go, the strategies its path and
// its copies' follow, and how many copies its splits made.
struct Life {
  int bin = 0;
  int light_bin = 0;  // of the sheen's light grid, when booked apart (HalfVectorLobe::slot)
  Strategies st;
  Tally* tally = nullptr;
  FabricBinBooks* books = nullptr;
  Vec3 wi;                // towards the light, in the cloth's frame
  size_t first_exit = 0;  // its exits are merged per cell from here on (tally_exit)
  int copies = 0;
};

// What a task's particles reuse: copies waiting to be traced on from where they were split, and
// the per-strategy albedo sums of a scattering.
struct TaskScratch {
  std::vector<Particle> pending;
  std::vector<double> s_sum;
  Particle probe;  // a next-event draw's particle (its vectors reused)
};

// What book_sheen left for the cells.
enum class CellsBook { whole, rest, none };

// The sheen's part of an exit along d with weights w whose shares sheen_share were reflected off
// the first fiber's surface (Particle::sheen), or all of it (SheenLight::reflected): booked into
// the window bin of its half vector, the rest into 'rest'. Says what the cells take: the whole
// exit (none booked here; 'rest' unset), 'rest', or nothing.
CellsBook book_sheen(const Tracer& t, Life& life, const Vec3& d, std::span<const double> w,
                     std::span<const double> sheen_share, std::span<double> rest) {
  const bool all = t.o.sheen_light == SheenLight::reflected;
  if (!t.sheen || (!all && sheen_share.empty())) return CellsBook::whole;
  const Vec3 wo = world_to_cloth(d), sum = life.wi + wo;
  if (!(wo.z * life.wi.z > 0) || !(length(sum) > 0)) return CellsBook::whole;
  const Vec3 h = sum / length(sum);
  const int k = t.sheen->window_bin_of(h);
  if (k < 0) return CellsBook::whole;
  std::array<double, kNumBands> part;  // the first w.size() are written and read
  for (size_t c = 0; c < w.size(); ++c) {
    part[c] = all ? w[c] : w[c] * sheen_share[c];
    rest[c] = w[c] - part[c];
  }
  const uint64_t cell =
      t.sheen_first_cell +
      t.sheen->slot(life.light_bin) * static_cast<uint64_t>(t.sheen->window_bins()) +
      static_cast<uint64_t>(k);
  tally_exit(*life.tally, life.first_exit, cell, std::span<const double>(part.data(), w.size()));
  return all ? CellsBook::none : CellsBook::rest;
}

// A reflected exit along d about the narrow light's plane of incidence, with weights w: into its
// bin of the plane (LightPlane::bin_of), as f over the bin's angles.
void book_plane_exit(const Tracer& t, Life& life, const Vec3& d, std::span<const double> w) {
  double factor = 0;
  const int k = t.plane->bin_of(world_to_cloth(d), factor);
  if (k < 0) return;
  std::array<double, kNumBands> f;  // the first w.size() are written and read
  for (size_t c = 0; c < w.size(); ++c) f[c] = w[c] * factor;
  tally_exit(*life.tally, life.first_exit, t.plane_first_cell + static_cast<uint64_t>(k),
             std::span<const double>(f.data(), w.size()));
}

// An exit along d whose line passes through p, with weights w: into the table's tally (its
// sheen's part, when booked apart, into the sheen's window) and, when on, the weave's.
void book_exit(const Tracer& t, Life& life, const Vec3& p, const Vec3& d, std::span<const double> w,
               std::span<const double> sheen_share) {
  const uint64_t cell = exit_cell(t.grid, life.bin, d);
  record_op(t, *life.tally, {0, static_cast<int64_t>(cell), 0, PathOp::book});
  std::array<double, kNumBands> rest;  // written by book_sheen before any read
  const std::span<double> r(rest.data(), w.size());
  const CellsBook cells = book_sheen(t, life, d, w, sheen_share, r);
  if (cells != CellsBook::none)
    tally_exit(*life.tally, life.first_exit, cell,
               cells == CellsBook::rest ? std::span<const double>(r) : w);
  if (t.plane) book_plane_exit(t, life, d, w);
  if (t.weave) {
    const int exit_bin = static_cast<int>(cell - static_cast<uint64_t>(life.bin) * t.grid.bins());
    tally_weave_exit(*t.weave, life.tally->weave, life.first_exit, life.bin, exit_bin, p, d, w);
  }
}

// The next-event estimate at a crossing x (FabricRaytraceOptions::next_event_rays): draws of the
// step s is about to take, weighed as its own would be and followed out of the slab without
// scattering; each that leaves books its weights over the count into its cell.
void book_next_events(const Tracer& t, Life& life, const SurfaceHit& h, const Crossings& x,
                      const Particle& s, TaskScratch& scratch, Rng& rng) {
  const double share = 1.0 / t.o.next_event_rays;
  Particle& probe = scratch.probe;
  const YarnShading y = shading_at(t, h);
  for (int k = 0; k < t.o.next_event_rays; ++k) {
    const std::optional<ScatterDraw> draw = draw_scatter(*y.fs, life.st, x, scratch.s_sum, rng);
    if (!draw) return;  // the fiber absorbs all of the hero's light
    probe.d = s.d;
    probe.w = s.w, probe.pdf = s.pdf, probe.wp = s.wp;
    const FiberPoint& pt = x.pts[draw->point];
    probe.sheen.assign(t.sheen && !s.scattered && y.fs->lobe ? s.w.size() : 0, 0.0);
    if (y.fs->lobe)
      weigh_scatter_lobe(*y.fs, *y.fiber, life.st, pt, *draw, scratch.s_sum, probe, probe.sheen);
    else
      weigh_scatter(*y.fs, *y.fiber, life.st, pt.bin, draw->exit_bin, scratch.s_sum, probe);
    if (!h.on_fiber() && y.tube) weigh_as_round_fiber(*y.tube, t.tube_proposal, x, s.d, probe);
    leave_fiber(pt.hit, draw->wo_local, probe);
    const std::optional<Vec3> out =
        escape_direction(t.scene, t.slab, t.curves, probe, 100 * t.o.max_scatterings);
    if (!out) continue;
    for (double& w : probe.w) w *= share;
    book_exit(t, life, probe.p, *out, probe.w, probe.sheen);
  }
}

// Scattering at the fiber the particle's line met at h (its weights' mean mean_w): false when the
// particle's life ends there, absorbed or at the scattering cap (its weight booked as lost).
bool scatter(const Tracer& t, Life& life, const SurfaceHit& h, double mean_w, Particle& s,
             TaskScratch& scratch, Rng& rng) {
  FabricBinBooks& books = *life.books;
  std::vector<double>& s_sum = scratch.s_sum;
  if (h.on_fiber() && dot(s.d, h.ng) >= 0) ++books.inside_hits;
  const Crossings x = crossings_of(t.scene, h, s.d, t.fs.grid);
  const YarnShading y = shading_at(t, h);
  albedo_sums(*y.fs, life.st, x, s_sum);
  if (t.o.next_event_rays > 0) book_next_events(t, life, h, x, s, scratch, rng);
  const std::optional<ScatterDraw> draw = draw_scatter(*y.fs, life.st, x, s_sum, rng);
  if (!draw) {  // the fiber absorbs all of the hero's light
    books.absorbed += mean_w;
    return false;
  }
  const FiberPoint& pt = x.pts[draw->point];
  double mean_pdf = 0;
  // The sheen is the first scattering's lobe light, while it scatters no more.
  s.sheen.assign(t.sheen && !s.scattered && y.fs->lobe ? s.w.size() : 0, 0.0);
  books.absorbed +=
      y.fs->lobe
          ? weigh_scatter_lobe(*y.fs, *y.fiber, life.st, pt, *draw, s_sum, s, s.sheen)
          : weigh_scatter(*y.fs, *y.fiber, life.st, pt.bin, draw->exit_bin, s_sum, s, &mean_pdf);
  record_op(t, *life.tally, {mean_pdf, pt.bin, draw->exit_bin, PathOp::scatter});
  if (!h.on_fiber() && y.tube) {
    record_op(t, *life.tally,
              {dot(s.d, x.pts[0].hit.shading.s), x.pts[0].bin, x.count > 1 ? x.pts[1].bin : -1,
               PathOp::tube});
    books.absorbed += weigh_as_round_fiber(*y.tube, t.tube_proposal, x, s.d, s);
  }
  leave_fiber(pt.hit, draw->wo_local, s);
  s.scattered = true;
  ++books.scatterings;
  if (++s.events >= t.o.max_scatterings) {
    books.lost += mean_weight(s.w);
    return false;
  }
  return true;
}

// Russian roulette below the weight window, splitting above it: false when roulette ends the
// particle.
bool keep_in_window(const Tracer& t, Life& life, Particle& s, std::vector<Particle>& pending,
                    Rng& rng) {
  const Steering w = steering_of(s);
  const double steer = t.window ? w.max_w : w.mean_p;
  double divided_by = 0;
  if (!survives_roulette(steer, t.o.roulette_threshold, w.mean_w, s, *life.books, rng, &divided_by))
    return false;
  if (divided_by > 0) record_op(t, *life.tally, {divided_by, 0, 0, PathOp::divide});
  // Splitting above the window: a fiber's albedo along one line, A' + A'', exceeds 1 where the
  // line runs near its axis (up to ~3 in red for red cotton), so weights grow along a path; a few
  // heavy paths would carry much of the table. n copies of weight w / n each, which go their own
  // ways from the next fiber on.
  const int max_copies = t.o.max_copies_per_particle;
  if (t.window && w.max_w > t.o.split_threshold && life.copies < max_copies) {
    const int n = split_count(w.max_w, t.o.split_threshold, max_copies - life.copies);
    record_op(t, *life.tally, {0, n, 0, PathOp::split});
    split(s, n, pending);
    life.books->splits += n - 1;
    life.copies += n - 1;
  }
  return true;
}

// Follows a particle (or copy) from event to event until it leaves the slab, is absorbed, lost or
// killed; the copies it splits off wait in scratch.pending.
void follow(const Tracer& t, Life& life, Particle& s, TaskScratch& scratch, Rng& rng) {
  FabricBinBooks& books = *life.books;
  while (true) {
    const double mean_w = mean_weight(s.w);
    SurfaceHit h;
    const Flight flight = fly(t.scene, t.slab, t.curves, s, &h);
    if (flight == Flight::left_slab) {  // binned by its direction, unless next events did
      // or, having met nothing, the straight-through part is computed (straight_through.h)
      const bool binned =
          s.scattered ? t.o.next_event_rays == 0 : t.o.straight_through == StraightThrough::sampled;
      if (binned) book_exit(t, life, s.p, s.d, s.w, s.sheen);
      books.exited += mean_w;
      return;
    }
    if (flight == Flight::hit && !passes_own_tube(h, s)) {
      if (!scatter(t, life, h, mean_w, s, scratch, rng)) return;
      if (!keep_in_window(t, life, s, scratch.pending, rng)) return;
      continue;
    }
    // Through a side of the repeat and in again through the opposite one, or out of its own tube.
    if (flight == Flight::wrapped)
      ++books.wraps;
    else
      ++books.tube_passes;
    if (++s.events > 100 * t.o.max_scatterings) {
      books.lost += mean_w;
      return;
    }
  }
}

// A particle's launch when particles are launched in lattice blocks
// (FabricRaytraceOptions::launch_lattice): the block's direction, and its point of the block's
// lattice through the block's entry point, both drawn as a particle's launch from the block's own
// stream (seed, bin, block + 1; a task's is (seed, task, 0)), so that they do not depend on how the
// particles are split into tasks. The block's particles share the direction: whether a line
// passes between the fibers depends on where it enters in concert with its direction (the gaps'
// shadow moves across the repeat as the direction tilts), and on a lattice of one direction the
// block's lines cover the gaps evenly.
// 'idx' is the particle's place in its bin; its launch stratum is taken as trace_particle gives it.
Launch lattice_launch(const Tracer& t, uint64_t idx, int bin, int strata, int stratum) {
  const uint64_t count = static_cast<uint64_t>(t.o.launch_lattice);
  Rng block(t.o.seed, static_cast<uint64_t>(bin), idx / count + 1);
  Launch l = launch(t.grid, t.slab, bin, block, strata, stratum);
  l.p = lattice_point(t.slab, l.p, static_cast<int>(idx % count), t.o.launch_lattice);
  return l;
}

// Launches particle k (of incident bin 'bin') and follows it and the copies its splits make; its
// exits are merged per cell with those of its sample unit from unit_first on.
void trace_particle(const Tracer& t, uint64_t k, int bin, Tally& tally, size_t unit_first,
                    TaskScratch& scratch, Rng& rng) {
  Life life;
  life.bin = bin;
  life.tally = &tally;
  life.books = &tally.books_of(bin);
  const int strata = t.sheen ? t.sheen->light_factor() : 1;
  const uint64_t idx = k - t.per_bin * static_cast<uint64_t>(bin);
  const int stratum = launch_stratum(t, idx);
  // Drawn either way: the stream stays the same.
  Launch l = launch(t.grid, t.slab, bin, rng, strata, stratum);
  if (t.o.launch_lattice > 1) l = lattice_launch(t, idx, bin, strata, stratum);
  if (t.plane) {  // the narrow light's direction in place of the bin's
    const Vec3 wi = t.plane->draw(rng);
    l.w0 = wi.z;
    l.d = -cloth_to_world(wi);
  }
  if (t.sheen)
    life.light_bin = t.sheen->light_bin_at(static_cast<size_t>(bin) * (strata * strata) + stratum);
  life.wi = -world_to_cloth(l.d);
  life.st = draw_strategies(t.mis, t.fs.groups, rng);
  life.books->launched += l.w0;
  ++life.books->particles;
  life.first_exit = unit_first;
  scratch.pending.clear();
  scratch.pending.push_back(launched_particle(l, t.nc, life.st, t.proposal));
  record_op(t, tally, {l.w0, 0, 0, PathOp::launch});
  while (!scratch.pending.empty()) {
    Particle s = std::move(scratch.pending.back());
    scratch.pending.pop_back();
    record_op(t, tally, {0, 0, 0, PathOp::pop});
    follow(t, life, s, scratch, rng);
  }
}

// The particles [first, first + count) of one task, on the task's stream: those of the bins not
// asked for are traced (the stream stays that of the whole run) but not tallied.
void trace_task(const Tracer& t, uint64_t first, uint64_t count, Rng& rng, Tally& task_tally) {
  if (first + count <= t.first_item || first >= t.last_item) return;
  TaskScratch scratch;
  scratch.s_sum.resize(t.mis ? t.fs.groups : 1);
  Tally outside;
  const Tally* last = nullptr;
  size_t unit_first = 0;
  for (uint64_t k = first; k < first + count; ++k) {
    const int bin = static_cast<int>(k / t.per_bin);
    Tally& tally = k >= t.first_item && k < t.last_item ? task_tally : outside;
    // A sample unit (a particle, or a launch block's part in this task) starts here.
    if (&tally != last || (k - t.per_bin * static_cast<uint64_t>(bin)) % t.o.launch_lattice == 0) {
      unit_first = tally.exits.size();
      record_op(t, tally, {0, 0, 0, PathOp::unit});
    }
    last = &tally;
    trace_particle(t, k, bin, tally, unit_first, scratch, rng);
  }
}

// The independent sample units of incident bin 'bin' (their exits are merged per cell): its launch
// blocks (particles, without the lattice), a block split by a task's start counting twice.
uint64_t sample_units(const Tracer& t, uint64_t items_per_task, int bin) {
  const uint64_t m = static_cast<uint64_t>(t.o.launch_lattice);
  const uint64_t begin = t.per_bin * static_cast<uint64_t>(bin), end = begin + t.per_bin;
  uint64_t units = (t.per_bin + m - 1) / m;
  for (uint64_t s = (begin / items_per_task + 1) * items_per_task; s < end; s += items_per_task)
    units += (s - begin) % m != 0;
  return units;
}

// How many of a bin's particles each launch stratum (launch_stratum) has: the particles of each
// of the sheen's light bins nested in it, in the order of HalfVectorLobe::slot.
std::vector<uint64_t> stratum_particles(const Tracer& t) {
  std::vector<uint64_t> n(static_cast<size_t>(t.sheen->light_bins_per_cell()), 0);
  for (uint64_t idx = 0; idx < t.per_bin; ++idx) ++n[static_cast<size_t>(launch_stratum(t, idx))];
  return n;
}

// A fiber table's rest and its surface lobe's cells (FiberSampler), held for a run.
struct HeldLobe {
  TabulatedBsdfTable rest;
  std::vector<double> cells;
};

// The table a scattering weighs with and the sampler it draws from. Where the table names a
// surface lobe and 'exact' (fiber detail, no proposal): its rest and the exact lobe, so that a
// filament's first-surface reflection is never averaged over a cell; else the table as it is (its
// cells include any lobe: a yarn tube's line albedo and a proposal's reweighting take the cells).
std::pair<const TabulatedBsdfTable*, FiberSampler> shading_tables(const TabulatedBsdfTable& t,
                                                                  bool exact, int threads,
                                                                  std::deque<HeldLobe>& held) {
  if (!exact || !t.surface_lobe) return {&t, FiberSampler(t)};
  HeldLobe& h = held.emplace_back();
  h.rest = t.without_surface_lobe("fiber", threads, &h.cells);
  return {&h.rest, FiberSampler(h.rest, *t.surface_lobe, h.cells)};
}

// The samplers and line albedos of the per-yarn tables after the first (the tracer's own), held
// for the run at stable addresses.
struct PerYarnHeld {
  std::deque<FiberSampler> samplers;
  std::deque<LineAlbedo> tubes;
  std::deque<HeldLobe> lobes;
};

// The tracer's shadings for two or more distinct tables f (table 0 the tracer's own fiber, no
// proposal) and which table each fiber and yarn tube of the sample takes.
void shade_per_yarn(const WovenSample& sample, const FiberTables& f, Tracer& t, PerYarnHeld& held) {
  for (size_t k = 0; k < f.tables.size(); ++k) {
    YarnShading y{&t.fs, &t.fiber, t.tube};
    if (k > 0) {
      auto [table, sampler] = shading_tables(*f.tables[k], !t.tube, t.o.threads, held.lobes);
      y.fs = &held.samplers.emplace_back(std::move(sampler));
      y.fiber = table;
      y.tube = t.tube ? &held.tubes.emplace_back(*f.tables[k]) : nullptr;
    }
    t.shadings.push_back(y);
  }
  const FiberCurves& c = sample.fibers;
  for (size_t i = 0; i < c.curve_count(); ++i)
    t.table_of_curve.push_back(f.table_of_yarn.empty() ? 0 : f.table_of_yarn[c.curve_yarn[i]]);
  t.table_of_mesh = f.table_of_mesh;
  t.table_of_mesh.resize(sample.meshes.size(), 0);
}

// The tracer of a run from its options; the scene and the sampler stay the caller's.
Tracer tracer_for(const RenderScene& scene, const RepeatSlab& slab, int64_t curves,
                  const FiberSampler& fs, const TabulatedBsdfTable& fiber,
                  const FabricRaytraceOptions& o) {
  Tracer t{.scene = scene,
           .slab = slab,
           .curves = curves,
           .fs = fs,
           .fiber = fiber,
           .o = o,
           .grid = DirectionGrid{o.resolution},
           .nc = fiber.channels};
  // Per particle: the channel weights w and, per sampling strategy j, the density p_j of its path
  // so far relative to their mean. With spectral MIS the strategies are the channel groups
  // (FiberSampler): each particle draws its path for one hero group h (uniform), and weights
  // channel c by the balance heuristic over the groups' path densities (one-sample MIS,
  // docs/fabric-bsdf.md): w_c = w0 prod f_c / mean_j prod (g_j / S_j), S_j = A_j' + A_j'', g_j the
  // mean of f over group j. The weights do not depend on h, so roulette on them keeps the estimate
  // unbiased.
  t.mis = o.channel_sampling == ChannelSampling::spectral_mis && t.nc > 1;
  t.window = o.channel_sampling != ChannelSampling::mean;
  t.proposal = o.proposal != nullptr;
  t.per_bin = o.particles_per_bin;
  // A narrow light traces only the bin holding its direction.
  const int first = o.narrow_light ? t.grid.bin_of(LightPlane(*o.narrow_light).wi) : o.first_bin;
  const int last = o.narrow_light ? first + 1 : o.bin_count ? first + o.bin_count : t.grid.bins();
  t.first_item = t.per_bin * static_cast<uint64_t>(first);
  t.last_item = t.per_bin * static_cast<uint64_t>(last);
  return t;
}

// Every particle of every bin, in tasks of at most 2048 (the same at any thread count).
TaskBatch batch_for(const Tracer& t, const ProgressCallback& progress) {
  TaskBatch batch;
  batch.items = t.per_bin * static_cast<uint64_t>(t.grid.bins());
  batch.seed = t.o.seed;
  batch.threads = t.o.threads;
  batch.items_per_task = std::min<uint64_t>(t.per_bin, 2048);
  batch.progress = progress;
  batch.stage = "particles";
  return batch;
}

// The exact straight-through part of the bins traced (FabricRaytraceOptions::straight_through),
// per cell pair: the sum the particles of the bin would book there on average (per_bin times the
// power per particle) and that sum's variance; empty when sampled. With the weave tally, the same
// per WeaveSums cell into 'weave' (its sum and sum2 then hold the sum and its variance). A bin's
// rays go in slices of at most kStraightThroughRaysPerTask (its streams are the bin's, booked in
// ray order: the same bits at any thread count and slice size), so that the progress callback is
// asked between bounded pieces of work at any particles_per_bin; 'cancelled' set when it stops.
constexpr uint64_t kStraightThroughRaysPerTask = 8192;
CellSums straight_through_sums(const Tracer& t, WeaveSums& weave, const ProgressCallback& progress,
                               bool& cancelled) {
  if (t.o.straight_through == StraightThrough::sampled) return {};
  const int bins = t.grid.bins();
  const int first = t.o.first_bin, count = (t.o.bin_count ? first + t.o.bin_count : bins) - first;
  const StraightThroughPlan plan = straight_through_plan(t.per_bin);
  const uint64_t slices =
      (plan.rays() + kStraightThroughRaysPerTask - 1) / kStraightThroughRaysPerTask;  // per bin
  const double n = static_cast<double>(t.per_bin);
  CellSums exact{std::vector<double>(static_cast<size_t>(bins) * bins, 0.0),
                 std::vector<double>(static_cast<size_t>(bins) * bins, 0.0)};
  TaskBatch batch;
  batch.items = static_cast<uint64_t>(count) * slices;
  batch.seed = t.o.seed;
  batch.threads = t.o.threads;
  batch.items_per_task = 1;
  batch.progress = progress;
  batch.stage = "straight-through slices";
  if (t.weave) weave = weave_sums_for(*t.weave);
  StraightThroughBin bin_sums(plan.replicates);
  const auto book_bin = [&](int bin) {
    std::vector<StraightThroughCell> woven;
    for (const StraightThroughCell& c : bin_sums.finish(t.weave ? &woven : nullptr)) {
      exact.sum[c.cell] += n * c.power;
      exact.sum2[c.cell] += n * n * c.variance;
    }
    bin_sums = StraightThroughBin(plan.replicates);
    if (!t.weave) return;
    // The power leaves in every channel alike (its launch weight |cos theta_i|).
    const size_t nc = static_cast<size_t>(t.weave->channels);
    const size_t row = static_cast<size_t>(bin) * t.weave->per_bin();
    for (const StraightThroughCell& c : woven)
      for (size_t k = row + c.cell * nc; k < row + (c.cell + 1) * nc; ++k) {
        weave.sum[k] += n * c.power;
        weave.sum2[k] += n * n * c.variance;
      }
  };
  uint64_t merged = 0;
  const TaskBatchStatus status = run_batch<std::vector<StraightThroughExit>>(
      batch,
      [&](uint64_t, uint64_t item, uint64_t, Rng&, std::vector<StraightThroughExit>& exits) {
        const int bin = first + static_cast<int>(item / slices);
        const StraightThroughRays rays{
            t.scene, t.slab, t.grid, bin, plan, t.o.seed, 100 * t.o.max_scatterings, t.weave};
        exits = straight_through_slice(rays, item % slices * kStraightThroughRaysPerTask,
                                       kStraightThroughRaysPerTask);
      },
      [&](const std::vector<StraightThroughExit>& exits) {
        bin_sums.add(exits, t.weave != nullptr);
        if (++merged % slices == 0) book_bin(first + static_cast<int>(merged / slices) - 1);
      });
  cancelled = status.cancelled;
  return exact;
}

// What a recording keeps of its trace (recorded_paths.h) besides the tasks' steps.
void keep_record(const Tracer& t, const TabulatedBsdfTable& fiber, const CellSums& exact,
                 const std::vector<uint64_t>& units, const FabricRaytraceResult& result,
                 RecordedFabricPaths& record) {
  record.options = t.o;
  record.options.proposal = nullptr;
  record.proposal_checksum = fiber.checksum();
  record.fiber_resolution = fiber.resolution;
  record.channels = t.nc;
  record.yarn_tubes = t.tube != nullptr;
  record.exact_sum = exact.sum;
  record.exact_sum2 = exact.sum2;
  record.units = units;
  record.traced = result;
}

// The ray trace with the distinct tables f (one: the single-table call, bit for bit), its steps
// into 'record' where given.
FabricRaytraceResult trace(const WovenSample& sample, const FiberTables& f,
                           const FabricRaytraceOptions& o, const ProgressCallback& progress,
                           RecordedFabricPaths* record = nullptr) {
  const TabulatedBsdfTable& fiber = *f.tables[0];
  const bool per_yarn = f.tables.size() > 1;
  o.validate();
  fiber.validate("");
  if (fiber.kind != "fiber") throw Error("", "fiber", "expected a fiber table, got " + fiber.kind);
  for (size_t k = 0; k < f.tables.size(); ++k)
    check_fiber_energy(*f.tables[k], per_yarn ? fiber_table_field(f, k) : "fiber");
  if (per_yarn && o.proposal)
    throw Error("", "proposal",
                "the likelihood-ratio proposal takes one fiber table; this trace has " +
                    std::to_string(f.tables.size()) + " distinct per-yarn tables");
  if (o.sheen_h_resolution > 0)
    check_sheen_trace(o, DirectionGrid{o.resolution}.bins(),
                      sample.meshes.empty() && !o.proposal && fiber.surface_lobe && !per_yarn,
                      record != nullptr);
  const RepeatSlab slab = repeat_slab_of(sample);
  if (!(slab.px > 0 && slab.pz > 0 && slab.y1 > slab.y0))
    throw Error("", "sample", "the woven sample has no period or no thickness");
  FabricRaytraceResult cancelled;
  cancelled.cancelled = true;
  const std::optional<SceneDescription> geometry = tiled_geometry(sample, progress);
  if (!geometry) return cancelled;
  RenderSceneOptions build;
  build.build_progress = progress;
  const RenderScene scene(*geometry, build);
  if (scene.cancelled()) return cancelled;
  if (o.proposal) check_proposal(*o.proposal, fiber);
  // With a proposal, paths are drawn from it and the choices that end or split a path are made on
  // the weights it gives (wp); the traced table's weights (w) follow the same path, each step
  // multiplied by its f over the proposal's.
  std::deque<HeldLobe> lobes;
  const bool exact_lobe = sample.meshes.empty() && !o.proposal;
  const auto [traced, fs] = o.proposal ? std::pair{&fiber, FiberSampler(*o.proposal)}
                                       : shading_tables(fiber, exact_lobe, o.threads, lobes);
  Tracer t =
      tracer_for(scene, slab, static_cast<int64_t>(sample.fibers.curve_count()), fs, *traced, o);
  // Yarn tubes stand for round fibers: they return the tables' line albedos.
  std::optional<LineAlbedo> tube, tube_proposal;
  if (!sample.meshes.empty()) {
    t.tube = &tube.emplace(fiber);
    if (o.proposal) t.tube_proposal = &tube_proposal.emplace(*o.proposal);
  }
  PerYarnHeld held;
  if (per_yarn) shade_per_yarn(sample, f, t, held);
  t.record = record != nullptr;
  const int bins = t.grid.bins(), nc = t.nc;
  std::optional<HalfVectorLobe> sheen;
  if (o.sheen_h_resolution > 0) {
    sheen = HalfVectorLobe::zeros(o.resolution, o.sheen_h_resolution, o.sheen_window, nc,
                                  o.sheen_light_resolution);
    // Values over the fibers' Fresnel reflectance (at their channels' mean index), which varies
    // faster across the grazing light bins than the rest of the sheen.
    const std::vector<double>& ior = fiber.surface_lobe->ior;
    double mean_ior = 0;
    for (double n : ior) mean_ior += n / static_cast<double>(ior.size());
    sheen->fresnel_ior = mean_ior;
    t.sheen = &*sheen;
    t.sheen_first_cell = static_cast<uint64_t>(bins) * bins;
    for (uint64_t n : stratum_particles(t))
      if (n == 0)
        throw Error("", "samples",
                    "too few to launch particles from each of the sheen's " +
                        std::to_string(sheen->light_bins_per_cell()) +
                        " light bins per table bin: give at least " +
                        std::to_string(sheen->light_bins_per_cell() * t.o.launch_lattice));
  }
  std::optional<LightPlane> plane;
  if (o.narrow_light) {
    t.plane = &plane.emplace(*o.narrow_light);
    t.plane_first_cell = static_cast<uint64_t>(bins) * bins;
  }
  const size_t values =
      (static_cast<size_t>(bins) * bins + (sheen ? sheen->values.size() / nc : 0) +
       (plane ? static_cast<size_t>(plane->light.plane_bins()) : 0)) *
      static_cast<size_t>(nc);
  CellSums sums{std::vector<double>(values, 0.0), std::vector<double>(values, 0.0)};
  FabricRaytraceResult result;
  result.bin_books.resize(bins);
  std::optional<WeaveLayout> weave;
  WeaveSums weave_sums;
  if (o.weave_positions_u > 0) {
    t.weave =
        &weave.emplace(weave_layout(o, nc, slab.x0, slab.z0, slab.px, slab.pz, slab.y0, slab.y1));
    weave_sums = weave_sums_for(*weave);
  }
  const TaskBatchStatus status = run_batch<Tally>(
      batch_for(t, progress),
      [&](uint64_t, uint64_t first, uint64_t count, Rng& rng, Tally& tally) {
        trace_task(t, first, count, rng, tally);
      },
      [&](Tally& tally) {
        add_task(tally, nc, sums, result);
        if (weave) add_weave_task(*weave, tally.weave, weave_sums);
        if (record) record->tasks.push_back(std::move(tally.path_ops));
      });
  // A cancelled trace is discarded by every caller (a checkpoint keeps the pieces before it):
  // stop here rather than compute the straight-through light of bins never traced.
  result.cancelled = status.cancelled;
  if (result.cancelled) return result;
  std::vector<uint64_t> units(bins);
  const uint64_t per_task = batch_for(t, progress).items_per_task;
  for (int a = 0; a < bins; ++a) units[a] = sample_units(t, per_task, a);
  WeaveSums weave_exact;  // the computed straight-through light's part of the weave, if any
  const CellSums exact = straight_through_sums(t, weave_exact, progress, result.cancelled);
  if (result.cancelled) return result;
  tabulate(sums, exact, t.grid, nc, t.per_bin, units, result);
  if (sheen)
    add_booked_sheen(sums, stratum_particles(t), o.threads, std::move(*sheen), result.table);
  if (plane) {
    const int bin = static_cast<int>(t.first_item / t.per_bin);
    tabulate_plane(sums, t.plane_first_cell * nc, *plane, nc, result.bin_books[bin].launched,
                   units[bin], result);
  }
  fabric_raytrace_totals(result);
  describe(sample, fiber, o, result.table);
  if (exact_lobe && fiber.surface_lobe) result.table.metadata["fiber_surface_lobe"] = "exact";
  if (record) keep_record(t, fiber, exact, units, result, *record);
  if (per_yarn) describe_per_yarn(f, result.table);
  if (weave) {
    weave_bin_books(*weave, weave_sums, weave_exact, t.per_bin, units, result);
    weave_totals(weave->shape, result);
  }
  return result;
}

// The recorded paths re-weighted for 'fiber' (reweight_fabric_paths): the trace's batch of tasks,
// each task's steps replayed into its tally, the tallies summed and tabulated as the trace does.
FabricRaytraceResult reweight(const RecordedFabricPaths& p, const TabulatedBsdfTable& fiber,
                              int threads) {
  check_fiber_stand_in(fiber, p.fiber_resolution, p.channels, "fiber",
                       "the table re-weighting recorded paths must be a fiber table of the "
                       "proposal's resolution and channels");
  std::optional<LineAlbedo> tube;
  if (p.yarn_tubes) tube.emplace(fiber);
  const DirectionGrid grid{p.options.resolution};
  const int bins = grid.bins(), nc = p.channels;
  const uint64_t per_bin = p.options.particles_per_bin;
  CellSums sums{std::vector<double>(static_cast<size_t>(bins) * bins * nc, 0.0),
                std::vector<double>(static_cast<size_t>(bins) * bins * nc, 0.0)};
  FabricRaytraceResult result;
  result.bin_books = p.traced.bin_books;
  for (FabricBinBooks& b : result.bin_books)
    b.launched = b.exited = b.absorbed = b.lost = b.roulette_net = 0;
  TaskBatch batch;
  batch.items = per_bin * static_cast<uint64_t>(bins);
  batch.seed = p.options.seed;
  batch.threads = threads;
  batch.items_per_task = std::min<uint64_t>(per_bin, 2048);  // the trace's (batch_for)
  run_batch<Tally>(
      batch,
      [&](uint64_t task, uint64_t, uint64_t, Rng&, Tally& tally) {
        replay_path_ops(p.tasks.at(task), fiber, tube ? &*tube : nullptr, nc, tally);
      },
      [&](const Tally& tally) { add_task(tally, nc, sums, result); });
  tabulate(sums, {p.exact_sum, p.exact_sum2}, grid, nc, per_bin, p.units, result);
  fabric_raytrace_totals(result);
  // The trace's description, of this table (describe).
  result.table.metadata = p.traced.table.metadata;
  result.table.metadata["fiber_checksum"] = fiber.checksum();
  for (const char* key : {"spec_hash", "spec_name"}) {
    const auto it = fiber.metadata.find(key);
    if (it != fiber.metadata.end())
      result.table.metadata[std::string("fiber_") + key] = it->second;
    else
      result.table.metadata.erase(std::string("fiber_") + key);
  }
  return result;
}

}  // namespace
}  // namespace raytrace

RecordedFabricPaths record_fabric_paths(const WovenSample& sample,
                                        const TabulatedBsdfTable& proposal,
                                        const FabricRaytraceOptions& options) {
  if (options.first_bin != 0 || options.bin_count != 0)
    throw Error("", "bin_count", "recorded paths are of a whole trace, not of some bins");
  if (options.next_event_rays > 0)
    throw Error("", "next_event_rays", "the next-event estimate's draws are not recorded");
  if (options.weave_positions_u > 0)
    throw Error("", "weave_positions_u", "the weave tally is not recorded");
  if (options.narrow_light) throw Error("", "narrow_light", "a narrow light is not recorded");
  FabricRaytraceOptions o = options;
  o.proposal = &proposal;
  RecordedFabricPaths record;
  (void)raytrace::trace(sample, FiberTables{{&proposal}, {}, {}, {}}, o, no_progress(), &record);
  return record;
}

FabricRaytraceResult reweight_fabric_paths(const RecordedFabricPaths& paths,
                                           const TabulatedBsdfTable& fiber, int threads) {
  return raytrace::reweight(paths, fiber, threads);
}

FabricRaytraceResult raytrace_fabric_table(const WovenSample& sample,
                                           const TabulatedBsdfTable& fiber,
                                           const FabricRaytraceOptions& o,
                                           const ProgressCallback& progress) {
  return raytrace::trace(sample, FiberTables{{&fiber}, {}, {}, {}}, o, progress);
}

FabricRaytraceResult raytrace_fabric_table(const WovenSample& sample, const FiberTables& fibers,
                                           const FabricRaytraceOptions& o,
                                           const ProgressCallback& progress) {
  validate_fiber_tables(fibers, sample);
  return raytrace::trace(sample, distinct_fiber_tables(fibers), o, progress);
}

}  // namespace weft
