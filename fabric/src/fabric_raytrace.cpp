#include "weft/fabric/fabric_raytrace.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "weft/core/direction_grid.h"
#include "weft/core/distribution.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/task_batch.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

namespace weft {
namespace {

constexpr double kMetresPerMm = 1e-3;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

Vec3 cloth_to_world(const Vec3& c) {
  return {c.x, c.z, -c.y};
}
Vec3 world_to_cloth(const Vec3& w) {
  return {w.x, -w.z, w.y};
}

// The fiber table as the particle tracer draws from it: per light bin i and channel c the albedo
// A_c[i] = sum_o f_c[i][o] D_o and a distribution over exit cells o with weights f_c[i][o] D_o,
// and the same for the channels' mean (channel index nc: the estimator before spectral MIS);
// within a cell, directions are drawn in proportion to |cos theta|.
struct FiberSampler {
  const TabulatedBsdfTable* table = nullptr;
  DirectionGrid grid;
  int strategies = 0;  // channels + 1 (their mean)
  std::vector<double> areas, max_cos;
  std::vector<double> albedo;        // [i * strategies + s]
  std::vector<Distribution1D> rows;  // [i * strategies + s]

  explicit FiberSampler(const TabulatedBsdfTable& t) : table(&t), grid(t.grid()) {
    const int bins = grid.bins(), nc = t.channels;
    strategies = nc + 1;
    areas = grid.cosine_weighted_areas();
    max_cos.resize(bins);
    for (int b = 0; b < bins; ++b) {
      // A bound of |cos theta| over the cell (for rejection): its largest value on a lattice that
      // includes the edges, a little enlarged; the pole's cell reaches 1.
      double m = 0;
      for (int i = 0; i <= 16; ++i)
        for (int j = 0; j <= 16; ++j)
          m = std::max(
              m, std::abs(DirectionGrid::to_direction(grid.chart_point(b, i / 16.0, j / 16.0)).z));
      max_cos[b] = std::min(1.0, 1.02 * m + 1e-6);
    }
    albedo.assign(static_cast<size_t>(bins) * strategies, 0.0);
    rows.resize(static_cast<size_t>(bins) * strategies);
    std::vector<double> w(static_cast<size_t>(strategies) * bins);
    for (int i = 0; i < bins; ++i) {
      for (int o = 0; o < bins; ++o) {
        double mean = 0;
        for (int c = 0; c < nc; ++c) {
          const double f = t.at(i, o, c);
          w[static_cast<size_t>(c) * bins + o] = f * areas[o];
          mean += f;
        }
        w[static_cast<size_t>(nc) * bins + o] = mean / nc * areas[o];
      }
      for (int s = 0; s < strategies; ++s) {
        const std::span<const double> ws(w.data() + static_cast<size_t>(s) * bins, bins);
        for (double x : ws) albedo[static_cast<size_t>(i) * strategies + s] += x;
        rows[static_cast<size_t>(i) * strategies + s] = Distribution1D(ws);
      }
    }
  }

  double albedo_of(int bin, int s) const {
    return albedo[static_cast<size_t>(bin) * strategies + s];
  }
  const Distribution1D& row(int bin, int s) const {
    return rows[static_cast<size_t>(bin) * strategies + s];
  }
  // The table value that strategy s samples in proportion to.
  double value(int i, int o, int s) const {
    const int nc = table->channels;
    if (s < nc) return table->at(i, o, s);
    double mean = 0;
    for (int c = 0; c < nc; ++c) mean += table->at(i, o, c);
    return mean / nc;
  }

  // A direction in cell b with density proportional to |cos theta| (rejection against the bound).
  Vec3 cosine_direction_in(int b, Rng& rng) const {
    for (int tries = 0; tries < 1000; ++tries) {
      const Vec3 d = DirectionGrid::to_direction(grid.chart_point(b, rng.uniform(), rng.uniform()));
      if (rng.uniform() * max_cos[b] <= std::abs(d.z)) return d;
    }
    return grid.bin_center(b);  // a cell of vanishing cosine mass: never drawn in practice
  }
};

// Where a particle's line meets a fiber: the point and its local frame (x = axis, z = outward).
struct FiberPoint {
  SurfaceHit hit;
  Vec3 wi_local;  // towards where the light came from
  int bin = 0;
};

struct ExitRecord {
  uint64_t cell;   // incident bin * bins + exit bin
  uint32_t first;  // index of its channel weights in the task's weight list
};

// A copy of a split particle, waiting to be traced on from where it was split.
struct PendingCopy {
  Vec3 p, d;
  int events = 0;
  int64_t ignore = kNoFiber;
  bool in_tube = false;        // sent into the yarn tube it left (yarn detail)
  std::vector<double> w, pdf;  // channel weights, relative path densities (see the tracer)
  std::vector<double> wp;      // the weights under the proposal (with one; else empty)
};

// The most copies one split makes (the weights are divided by the count made, so any cap is
// unbiased; it bounds the work a freak weight can cause).
constexpr int kMaxSplit = 16;

struct TaskTally {
  std::vector<ExitRecord> exits;
  std::vector<double> weights;  // channels per exit
  // The books of the task's particles by incident bin (a task may straddle two bins): kept apart
  // so that every bin's books sum alike however the bins are split over runs.
  std::vector<std::pair<int, FabricBinBooks>> books;
  FabricBinBooks& books_of(int bin) {
    if (books.empty() || books.back().first != bin) books.emplace_back(bin, FabricBinBooks{});
    return books.back().second;
  }
};

// Where the line through 'h' along 'along' crosses the surface again, leaving the material it
// entered at h (the next hit whose normal faces along the line), within a few hits.
bool find_crossing(const RenderScene& scene, const SurfaceHit& h, const Vec3& along,
                   SurfaceHit* out) {
  SurfaceHit cur = h;
  for (int k = 0; k < 4; ++k) {
    if (!scene.intersect({cur.spawn_origin(along), along, 1e300}, out)) return false;
    if (dot(along, out->shading.n) > 0) return true;
    cur = *out;
  }
  return false;
}

// The repeat and its eight neighbours (weave.h tiled_woven_description with one copy on each
// side), for a renderer that only asks for geometry. Copy (i, k), shifted by (i Px, k Pz) with
// i, k in {-1, 0, 1}, is copy number 3 (i + 1) + (k + 1):
// copy q of the sample's mesh m is mesh 9 m + q; at fiber detail copy q is curve set q, and fiber
// c of the sample in it is fiber id q * curves + c (RenderScene numbers fibers set by set).
int copy_index(int i, int k) {
  return 3 * (i + 1) + (k + 1);
}

SceneDescription tiled_geometry(const WovenSample& sample) {
  if (sample.fibers.curve_count() == 0 && sample.meshes.empty())
    throw Error("", "detail",
                "the ray-traced estimator needs the sample's geometry (fibers or yarn tubes); "
                "this sample has none");
  SceneDescription d = tiled_woven_description(sample, 1, 1, "woven sample");
  MaterialBinding any;
  any.type = "lambert";
  any.field = "fabric estimator";
  d.default_material = any;
  return d;
}

// The fiber a particle ignores after it moved by one period through side 'side' (0: -x, 1: +x,
// 2: -z, 3: +z; the particle re-enters through the opposite side): the same fiber in the copy that
// now lies where it was, or none when that copy is not part of the tiling.
int64_t fiber_after_wrap(int64_t fiber, int side, int64_t curves) {
  if (fiber == kNoFiber) return kNoFiber;
  const int64_t q = fiber / curves, c = fiber % curves;
  int i = static_cast<int>(q / 3) - 1, k = static_cast<int>(q % 3) - 1;
  // Through -x the particle moves by +Px: what was at copy i is now at copy i + 1, relative to it.
  i += side == 0 ? 1 : side == 1 ? -1 : 0;
  k += side == 2 ? 1 : side == 3 ? -1 : 0;
  if (i < -1 || i > 1 || k < -1 || k > 1) return kNoFiber;
  return copy_index(i, k) * curves + c;
}

// Where the line through B' (a hit on a round fiber) along d leaves the fiber's cylinder: B'' with
// the fiber frame there (x along the axis, z outward). False when the line only grazes it.
bool fiber_exit_point(const RenderScene& scene, const SurfaceHit& entry, const Vec3& d,
                      SurfaceHit* out) {
  const FiberSegment seg = scene.fiber_segment(entry);
  const std::optional<double> t = cylinder_exit_distance(seg, entry.p, d);
  if (!t || *t <= 0) return false;
  *out = entry;
  out->p = entry.p + d * *t;
  out->t = entry.t + *t;
  const Vec3 axis = seg.tangent();
  const Vec3 radial = out->p - seg.axis_point(seg.closest_u(out->p));
  const Vec3 n = radial - axis * dot(radial, axis);
  const double len = length(n);
  if (!(len > 0)) return false;
  out->ng = n / len;
  out->shading = Frame(axis, cross(out->ng, axis), out->ng);
  return true;
}

}  // namespace

std::vector<Vec3> visible_fiber_tangents(const WovenSample& sample, bool from_above,
                                         int rays_per_side) {
  if (rays_per_side < 1 || rays_per_side > 4096)
    throw Error("", "rays_per_side", "must lie in [1, 4096]");
  const double px = sample.summary.period_x_mm * kMetresPerMm;
  const double pz = sample.summary.period_z_mm * kMetresPerMm;
  const double y0 = sample.summary.y_min_mm * kMetresPerMm;
  const double y1 = sample.summary.y_max_mm * kMetresPerMm;
  const RenderScene scene(tiled_geometry(sample));
  std::vector<Vec3> out;
  for (int i = 0; i < rays_per_side; ++i)
    for (int k = 0; k < rays_per_side; ++k) {
      const Vec3 p{-0.5 * px + px * (i + 0.5) / rays_per_side, from_above ? y1 + 1e-6 : y0 - 1e-6,
                   -0.5 * pz + pz * (k + 0.5) / rays_per_side};
      SurfaceHit h;
      if (scene.intersect({p, {0, from_above ? -1.0 : 1.0, 0}, 1e300}, &h))
        out.push_back(world_to_cloth(h.shading.s));
    }
  return out;
}

const char* channel_sampling_name(ChannelSampling s) {
  return s == ChannelSampling::mean ? "mean" : "hero";
}

void FabricRaytraceOptions::validate() const {
  if (resolution < 1 || resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (particles_per_bin < 1 || particles_per_bin > (uint64_t{1} << 36))
    throw Error("", "samples", "particles per incident bin must lie in [1, 2^36]");
  if (max_scatterings < 1) throw Error("", "max_scatterings", "must be >= 1");
  if (!(roulette_threshold > 0 && roulette_threshold < 1))
    throw Error("", "roulette_threshold", "must lie in (0, 1)");
  if (!(split_threshold > roulette_threshold) || !std::isfinite(split_threshold))
    throw Error("", "split_threshold", "must be finite and above roulette_threshold");
  if (max_copies_per_particle < 1 || max_copies_per_particle > (1 << 20))
    throw Error("", "max_copies_per_particle", "must lie in [1, 2^20]");
  if (threads < 0) throw Error("", "threads", "must be >= 0");
  const int bins = DirectionGrid{resolution}.bins();
  if (first_bin < 0 || bin_count < 0 || first_bin + bin_count > bins)
    throw Error("", "bin_count", "incident bins must lie in [0, " + std::to_string(bins) + ")");
}

void FabricBinBooks::add(const FabricBinBooks& o) {
  launched += o.launched, exited += o.exited, absorbed += o.absorbed, lost += o.lost;
  roulette_net += o.roulette_net;
  particles += o.particles, scatterings += o.scatterings, wraps += o.wraps, splits += o.splits;
  roulette_kills += o.roulette_kills, tube_passes += o.tube_passes;
  inside_hits += o.inside_hits;
}

void fabric_raytrace_totals(FabricRaytraceResult& r) {
  FabricBinBooks all;
  std::vector<double> noise2, signal2;
  for (const FabricBinBooks& b : r.bin_books) {
    all.add(b);
    noise2.resize(std::max(noise2.size(), b.noise2.size()), 0.0);
    signal2.resize(noise2.size(), 0.0);
    for (size_t c = 0; c < b.noise2.size() && c < b.signal2.size(); ++c) {
      noise2[c] += b.noise2[c];
      signal2[c] += b.signal2[c];
    }
  }
  r.particles = all.particles, r.scatterings = all.scatterings, r.wraps = all.wraps;
  r.splits = all.splits;
  r.inside_hits = all.inside_hits;
  r.roulette_kills = all.roulette_kills, r.tube_passes = all.tube_passes;
  r.splits_per_bin.assign(r.bin_books.size(), 0);
  r.roulette_kills_per_bin.assign(r.bin_books.size(), 0);
  for (size_t b = 0; b < r.bin_books.size(); ++b) {
    r.splits_per_bin[b] = r.bin_books[b].splits;
    r.roulette_kills_per_bin[b] = r.bin_books[b].roulette_kills;
  }
  r.exited = r.absorbed = r.lost = r.roulette_net = 0;
  if (all.launched > 0) {
    r.exited = all.exited / all.launched;
    r.lost = all.lost / all.launched;
    r.roulette_net = all.roulette_net / all.launched;
    r.absorbed = all.absorbed / all.launched;
  }
  // Each channel on its own, and all together as weft compare's rel_rms sums them.
  double all_noise2 = 0, all_signal2 = 0;
  r.relative_noise_per_channel.assign(noise2.size(), 0.0);
  for (size_t c = 0; c < noise2.size(); ++c) {
    r.relative_noise_per_channel[c] = signal2[c] > 0 ? std::sqrt(noise2[c] / signal2[c]) : 0;
    all_noise2 += noise2[c];
    all_signal2 += signal2[c];
  }
  r.relative_noise = all_signal2 > 0 ? std::sqrt(all_noise2 / all_signal2) : 0.0;
}

namespace {

// A fiber sends out at most the light that hits it: a table's total albedo (the bake's exit
// fraction) is at most 1. Above it, path weights grow from fiber to fiber, and the trace would run
// for minutes before they overflow (a synthetic table of total albedo 1.9 did: tens of CPU
// minutes), so it is refused before any work. The allowance is for a table's tabulation error:
// the classic fiber at reflectance 1 (lossless, total albedo 1 by construction) tabulates to
// at most kFiberAlbedoAllowance above 1 (test_fabric_raytrace.cpp).
constexpr double kFiberAlbedoAllowance = 0.01;

void check_fiber_energy(const TabulatedBsdfTable& t, const std::string& field) {
  const std::vector<double> a = t.total_albedo();
  for (size_t c = 0; c < a.size(); ++c)
    if (!(a[c] <= 1 + kFiberAlbedoAllowance)) {
      char v[32];
      std::snprintf(v, sizeof v, "%.4g", a[c]);
      throw Error("", field,
                  std::string("the fiber table's total albedo is ") + v + " in channel " +
                      std::to_string(c) +
                      ": a fiber sends out at most the light that hits it (at most 1, the bake's "
                      "exit fraction); bake it with weft bake fiber");
    }
}

}  // namespace

FabricRaytraceResult raytrace_fabric_table(const WovenSample& sample,
                                           const TabulatedBsdfTable& fiber,
                                           const FabricRaytraceOptions& o,
                                           const ProgressCallback& progress) {
  o.validate();
  fiber.validate("");
  if (fiber.kind != "fiber") throw Error("", "fiber", "expected a fiber table, got " + fiber.kind);
  check_fiber_energy(fiber, "fiber");
  const double px = sample.summary.period_x_mm * kMetresPerMm;
  const double pz = sample.summary.period_z_mm * kMetresPerMm;
  const double y0 = sample.summary.y_min_mm * kMetresPerMm;
  const double y1 = sample.summary.y_max_mm * kMetresPerMm;
  if (!(px > 0 && pz > 0 && y1 > y0))
    throw Error("", "sample", "the woven sample has no period or no thickness");
  const double x0 = -0.5 * px, z0 = -0.5 * pz;
  const RenderScene scene(tiled_geometry(sample));
  const auto curves = static_cast<int64_t>(sample.fibers.curve_count());
  if (o.proposal) {
    o.proposal->validate("");
    if (o.proposal->kind != "fiber" || o.proposal->resolution != fiber.resolution ||
        o.proposal->channels != fiber.channels)
      throw Error("", "proposal",
                  "the proposal must be a fiber table of the traced table's resolution and "
                  "channels");
    check_fiber_energy(*o.proposal, "proposal");
  }
  // With a proposal, paths are drawn from it and the choices that end or split a path are made on
  // the weights it gives (wp); the traced table's weights (w) follow the same path, each step
  // multiplied by its f over the proposal's.
  const bool reweight = o.proposal != nullptr;
  const TabulatedBsdfTable& drawn = reweight ? *o.proposal : fiber;
  const FiberSampler fs(drawn);
  const int nc = fiber.channels;
  const DirectionGrid grid{o.resolution};
  const int bins = grid.bins();
  const auto areas = grid.cosine_weighted_areas();
  const uint64_t per_bin = o.particles_per_bin;

  std::vector<double> sum(static_cast<size_t>(bins) * bins * nc, 0.0);
  std::vector<double> sum2(static_cast<size_t>(bins) * bins * nc, 0.0);
  FabricRaytraceResult result;
  result.bin_books.resize(bins);

  const uint64_t first_item = per_bin * static_cast<uint64_t>(o.first_bin);
  const uint64_t last_item =
      per_bin * static_cast<uint64_t>(o.bin_count ? o.first_bin + o.bin_count : bins);
  TaskBatch batch;
  batch.items = per_bin * static_cast<uint64_t>(bins);
  batch.seed = o.seed;
  batch.threads = o.threads;
  batch.items_per_task = std::min<uint64_t>(per_bin, 2048);
  batch.progress = progress;
  batch.stage = "particles";

  const TaskBatchStatus status = run_batch<TaskTally>(
      batch,
      [&](uint64_t, uint64_t first, uint64_t count, Rng& rng, TaskTally& task_tally) {
        if (first + count <= first_item || first >= last_item) return;
        // Per particle: the channel weights w and, per sampling strategy j, the density p_j of
        // its path so far relative to their mean. With spectral MIS the strategies are the
        // channels: each particle draws its path for one hero channel h (uniform), and weights
        // channel c by the balance heuristic over the channels' path densities (one-sample MIS,
        // docs/fabric-bsdf.md): w_c = w0 prod f_c / mean_j prod (f_j / S_j), S_j = A_j' + A_j''.
        // The weights do not depend on h, so roulette on them keeps the estimate unbiased.
        const bool mis = o.channel_sampling == ChannelSampling::spectral_mis && nc > 1;
        // Roulette on the largest weight and splitting: all but the estimator before (mean).
        const bool window = o.channel_sampling != ChannelSampling::mean;
        const int n_strategies = mis ? nc : 1;
        std::vector<double> w(nc), wp(reweight ? nc : 0), pdf(n_strategies), s_sum(n_strategies);
        std::vector<PendingCopy> pending;
        TaskTally outside;  // a task's particles of bins not asked for: traced, not tallied
        for (uint64_t k = first; k < first + count; ++k) {
          const int a = static_cast<int>(k / per_bin);
          TaskTally& tally = k >= first_item && k < last_item ? task_tally : outside;
          FabricBinBooks& books = tally.books_of(a);
          // The light: a direction of bin a (uniform in solid angle), flux per unit area
          // proportional to |cos theta_i|; entering the slab through the face it faces.
          const Vec3 wi_cloth =
              DirectionGrid::to_direction(grid.chart_point(a, rng.uniform(), rng.uniform()));
          const double w0 = std::abs(wi_cloth.z);
          const Vec3 d = -cloth_to_world(wi_cloth);
          const Vec3 p{x0 + px * rng.uniform(), wi_cloth.z > 0 ? y1 : y0, z0 + pz * rng.uniform()};
          // The strategy this particle's path follows (a FiberSampler strategy index).
          const int hero =
              mis ? std::min(nc - 1, static_cast<int>(rng.uniform() * nc)) : fs.strategies - 1;
          books.launched += w0;
          ++books.particles;
          // Copies of the particle made by splitting wait here; they share its hero channel. Its
          // exits are merged per cell (from first_exit on) so that the per-cell variance below
          // stays that of one particle's total.
          const size_t first_exit = tally.exits.size();
          pending.clear();
          int copies = 0;  // made by this particle's splits
          pending.push_back({p, d, 0, kNoFiber, false, std::vector<double>(nc, w0),
                             std::vector<double>(n_strategies, 1.0),
                             std::vector<double>(reweight ? nc : 0, w0)});
          while (!pending.empty()) {
            Vec3 p = pending.back().p, d = pending.back().d;
            int events = pending.back().events;
            int64_t ignore = pending.back().ignore;  // the fiber last left (fiber detail)
            bool in_tube = pending.back().in_tube;   // see PendingCopy
            w.swap(pending.back().w);
            pdf.swap(pending.back().pdf);
            wp.swap(pending.back().wp);
            pending.pop_back();
            while (true) {
              double mean_w = 0;
              for (double x : w) mean_w += x;
              mean_w /= nc;
              // Distances to the repeat's sides and to the slab's faces.
              double t_side = kInfinity;
              int side = -1;
              const double lo[2] = {x0, z0}, hi[2] = {x0 + px, z0 + pz};
              const double pc[2] = {p.x, p.z}, dc[2] = {d.x, d.z};
              for (int ax = 0; ax < 2; ++ax) {
                if (dc[ax] > 0 && (hi[ax] - pc[ax]) / dc[ax] < t_side)
                  t_side = (hi[ax] - pc[ax]) / dc[ax], side = 2 * ax + 1;
                if (dc[ax] < 0 && (lo[ax] - pc[ax]) / dc[ax] < t_side)
                  t_side = (lo[ax] - pc[ax]) / dc[ax], side = 2 * ax;
              }
              t_side = std::max(0.0, t_side);
              const double t_slab = d.y > 0   ? (y1 - p.y) / d.y
                                    : d.y < 0 ? (y0 - p.y) / d.y
                                              : kInfinity;
              SurfaceHit h;
              if (!scene.intersect({p, d, std::min(t_side, t_slab)}, &h, ignore)) {
                if (t_slab <= t_side) {  // left the cloth: binned by its direction
                  const int exit_bin = grid.bin_of(world_to_cloth(d));
                  const uint64_t cell = static_cast<uint64_t>(a) * bins + exit_bin;
                  size_t e = first_exit;
                  while (e < tally.exits.size() && tally.exits[e].cell != cell) ++e;
                  if (e < tally.exits.size()) {
                    for (int c = 0; c < nc; ++c) tally.weights[tally.exits[e].first + c] += w[c];
                  } else {
                    tally.exits.push_back({cell, static_cast<uint32_t>(tally.weights.size())});
                    tally.weights.insert(tally.weights.end(), w.begin(), w.end());
                  }
                  books.exited += mean_w;
                  break;
                }
                // Through a side of the repeat: in again through the opposite one.
                p += t_side * d;
                if (side == 0) p.x += px;
                if (side == 1) p.x -= px;
                if (side == 2) p.z += pz;
                if (side == 3) p.z -= pz;
                ignore = fiber_after_wrap(ignore, side, curves);
                if (++books.wraps, ++events > 100 * o.max_scatterings) {
                  books.lost += mean_w;
                  break;
                }
                continue;
              }
              // Light that a yarn tube sent into itself leaves it through its far side, as light
              // leaves a fiber through the fiber itself: the table already holds the whole yarn's
              // part (taking that exit as a new crossing scattered it twice, and only when it left
              // into the tube, which made the yarn-detail tables non-reciprocal).
              if (in_tube && !h.on_fiber() && dot(d, h.ng) > 0) {
                p = h.spawn_origin(d);
                in_tube = false;
                ++books.tube_passes;
                if (++events > 100 * o.max_scatterings) {
                  books.lost += mean_w;
                  break;
                }
                continue;
              }
              in_tube = false;
              if (h.on_fiber() && dot(d, h.ng) >= 0) ++books.inside_hits;
              // The line meets a fiber at B' and would leave it at B''. A round fiber's B'' is
              // where the line leaves its cylinder. Yarn tubes that press on each other share
              // surfaces, so a particle may find itself inside one: then this hit is B'' and B'
              // lies behind it. The scene never returns a fiber hit from inside (RenderScene:
              // a ray inside a fiber passes through it, as it passes through its own fiber); a
              // hit counted here grazed the surface (taken alone, without B'').
              FiberPoint pts[2];
              int n_pts = 0;
              const bool from_outside = dot(d, h.ng) < 0;
              pts[n_pts++].hit = h;
              SurfaceHit other;
              if (h.on_fiber()) {
                if (from_outside && fiber_exit_point(scene, h, d, &other)) pts[n_pts++].hit = other;
              } else if (find_crossing(scene, h, from_outside ? d : -d, &other)) {
                pts[n_pts++].hit = other;
              }
              // Per strategy j the sum S_j of the albedos at the crossings; the hero picks B' or
              // B'' in proportion to its own and draws an exit cell o from its row there, with
              // probability (A_h(q) / S_h) (f_h D_o / A_h(q)) = f_h D_o / S_h.
              for (int q = 0; q < n_pts; ++q) {
                // On a yarn tube the table's frame is the facet's (its normal, the yarn's tangent
                // in its plane), not the interpolated shading normal: light arrives on a facet in
                // proportion to its cosine with the facet, and leaves drawn by the cosine with the
                // frame's normal; the two normals differing would make the transport
                // non-reciprocal (Veach's thesis, 1997, ch. 5, on shading normals).
                if (!pts[q].hit.on_fiber())
                  pts[q].hit.shading =
                      Frame::from_normal_tangent(pts[q].hit.ng, pts[q].hit.shading.s);
                pts[q].wi_local = pts[q].hit.shading.to_local(-d);
                pts[q].bin = fs.grid.bin_of(pts[q].wi_local);
              }
              auto strategy = [&](int j) { return mis ? j : fs.strategies - 1; };
              for (int j = 0; j < n_strategies; ++j) {
                s_sum[j] = 0;
                for (int q = 0; q < n_pts; ++q) s_sum[j] += fs.albedo_of(pts[q].bin, strategy(j));
              }
              const int hj = mis ? hero : 0;
              const double a_hero0 = fs.albedo_of(pts[0].bin, hero);
              if (!(s_sum[hj] > 0)) {  // the fiber absorbs all of the hero's light
                books.absorbed += mean_w;
                break;
              }
              const int q = n_pts == 2 && rng.uniform() * s_sum[hj] >= a_hero0 ? 1 : 0;
              const FiberPoint& pt = pts[q];
              const int ob = static_cast<int>(fs.row(pt.bin, hero).sample_discrete(rng.uniform()));
              const Vec3 wo_local = fs.cosine_direction_in(ob, rng);
              // Throughput f_c D_o over the strategies' mean probability of this step (D_o and the
              // within-cell density are common to all and cancel); densities kept relative to
              // their mean so that long paths neither underflow nor overflow.
              double mean_pdf = 0;
              for (int j = 0; j < n_strategies; ++j) {
                pdf[j] *= s_sum[j] > 0 ? fs.value(pt.bin, ob, strategy(j)) / s_sum[j] : 0.0;
                mean_pdf += pdf[j];
              }
              mean_pdf /= n_strategies;
              double before = 0, after = 0;
              for (int c = 0; c < nc; ++c) {
                before += w[c];
                w[c] *= fiber.at(pt.bin, ob, c) / mean_pdf;
                after += w[c];
              }
              if (reweight)
                for (int c = 0; c < nc; ++c) wp[c] *= drawn.at(pt.bin, ob, c) / mean_pdf;
              for (double& x : pdf) x /= mean_pdf;
              books.absorbed += (before - after) / nc;
              d = normalize(pt.hit.shading.to_world(wo_local));
              p = pt.hit.spawn_origin(d);
              ignore = pt.hit.fiber;  // light leaves a fiber through the fiber itself
              in_tube = !pt.hit.on_fiber() && dot(d, pt.hit.ng) < 0;  // into its own yarn tube
              ++books.scatterings;
              if (++events >= o.max_scatterings) {
                double m = 0;
                for (double x : w) m += x;
                books.lost += m / nc;
                break;
              }
              // Russian roulette on the largest channel weight (on their mean before spectral
              // MIS, which let the dominant channel's weights grow where the mean fell).
              mean_w = 0;
              double max_w = 0;
              for (double x : w) mean_w += x;
              mean_w /= nc;
              double mean_p = 0;  // the deciding weights' mean: w's, or the proposal's
              for (double x : reweight ? wp : w) mean_p += x, max_w = std::max(max_w, x);
              mean_p /= nc;
              const double steer = window ? max_w : mean_p;
              if (steer < o.roulette_threshold) {
                const double survive = steer / (o.roulette_threshold);
                if (rng.uniform() < survive) {
                  for (double& x : w) x /= survive;
                  for (double& x : wp) x /= survive;
                  books.roulette_net -= mean_w / survive - mean_w;
                } else {
                  books.roulette_net += mean_w;
                  ++books.roulette_kills;
                  break;
                }
              }
              // Splitting above the window: a fiber's albedo along one line, A' + A'', exceeds 1
              // where the line runs near its axis (up to ~3 in red for red cotton), so weights grow
              // along a path; a few heavy paths would carry much of the table. n copies of weight
              // w / n each, which go their own ways from the next fiber on.
              if (window && max_w > o.split_threshold && copies < o.max_copies_per_particle) {
                const int n = static_cast<int>(
                    std::min<double>({double(kMaxSplit), std::ceil(max_w / o.split_threshold),
                                      double(o.max_copies_per_particle - copies + 1)}));
                for (double& x : w) x /= n;
                for (double& x : wp) x /= n;
                for (int copy = 1; copy < n; ++copy)
                  pending.push_back({p, d, events, ignore, in_tube, w, pdf, wp});
                books.splits += n - 1;
                copies += n - 1;
              }
            }
          }
        }
      },
      [&](const TaskTally& t) {
        for (const auto& e : t.exits)
          for (int c = 0; c < nc; ++c) {
            const double x = t.weights[e.first + c];
            sum[e.cell * nc + c] += x;
            sum2[e.cell * nc + c] += x * x;
          }
        for (const auto& [a, b] : t.books) result.bin_books[a].add(b);
      });

  result.cancelled = status.cancelled;
  TabulatedBsdfTable& table = result.table;
  table.resolution = o.resolution;
  table.channels = nc;
  table.kind = "fabric";
  table.values.assign(static_cast<size_t>(bins) * bins * nc, 0.0f);
  const double n = static_cast<double>(per_bin);
  const double omega = grid.bin_solid_angle();
  result.standard_error.assign(table.values.size(), 0.0f);
  for (int a = 0; a < bins; ++a) {
    std::vector<double>& noise2 = result.bin_books[a].noise2;
    std::vector<double>& signal2 = result.bin_books[a].signal2;
    noise2.assign(nc, 0.0);
    signal2.assign(nc, 0.0);
    for (int b = 0; b < bins; ++b) {
      const size_t cell = static_cast<size_t>(a) * bins + b;
      const double scale = omega / (n * areas[a] * areas[b]);
      const double w = areas[a] * areas[b];
      for (int c = 0; c < nc; ++c) {
        const size_t v = cell * nc + c;
        const double f = sum[v] * scale;
        table.values[v] = static_cast<float>(f);
        // Per particle the cell receives one exit or none: the sample variance of its weight.
        const double m1 = sum[v] / n;
        const double se = std::sqrt(std::max(0.0, sum2[v] / n - m1 * m1) / n) * n * scale;
        result.standard_error[v] = static_cast<float>(se);
        noise2[c] += se * se * w;
        signal2[c] += f * f * w;
      }
    }
  }
  // Weights that overflow mean a fiber table that returns more light than it receives at every
  // crossing (a baked table conserves energy over the whole fiber): refuse it, not a table of inf.
  for (float v : table.values)
    if (!std::isfinite(v))
      throw Error("", "fiber",
                  "the ray trace's path weights overflowed: the fiber table returns more light "
                  "than it receives along paths (its albedo at B' plus B'' stays above 1); bake "
                  "it with weft bake fiber");
  fabric_raytrace_totals(result);
  table.metadata = {{"method", "raytrace"},
                    {"estimator_revision", std::to_string(kFabricRaytraceRevision)},
                    {"fiber_checksum", fiber.checksum()},
                    {"particles_per_bin", std::to_string(per_bin)},
                    {"seed", std::to_string(o.seed)},
                    {"estimator", channel_sampling_name(o.channel_sampling)},
                    {"sample", sample.summary.source + " (" + sample.summary.detail + ")"}};
  if (reweight) table.metadata["proposal_checksum"] = o.proposal->checksum();
  if (o.channel_sampling != ChannelSampling::mean) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, o.split_threshold).ptr;
    table.metadata["split_threshold"] = std::string(text, end);
    table.metadata["max_copies_per_particle"] = std::to_string(o.max_copies_per_particle);
  }
  for (const char* key : {"spec_hash", "spec_name"})
    if (const auto it = fiber.metadata.find(key); it != fiber.metadata.end())
      table.metadata[std::string("fiber_") + key] = it->second;
  return result;
}

}  // namespace weft
