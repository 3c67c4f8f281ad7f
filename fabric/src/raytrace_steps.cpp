#include "weft/fabric/raytrace_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "weft/core/error.h"

namespace weft::raytrace {
namespace {

constexpr double kMetresPerMm = 1e-3;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

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

RepeatSlab repeat_slab_of(const WovenSample& sample) {
  RepeatSlab r;
  r.px = sample.summary.period_x_mm * kMetresPerMm;
  r.pz = sample.summary.period_z_mm * kMetresPerMm;
  r.y0 = sample.summary.y_min_mm * kMetresPerMm;
  r.y1 = sample.summary.y_max_mm * kMetresPerMm;
  r.x0 = -0.5 * r.px, r.z0 = -0.5 * r.pz;
  return r;
}

double mean_weight(std::span<const double> w) {
  double mean = 0;
  for (double x : w) mean += x;
  return mean / static_cast<double>(w.size());
}

Launch launch(const DirectionGrid& grid, const RepeatSlab& slab, int bin, Rng& rng, int strata,
              int stratum) {
  // Which of the two chart draws is made first is the compiler's choice (an unspecified order of
  // evaluation), kept as it is so that the tables keep their bits ((0 + u) / 1 is u exactly).
  const double m = strata;
  const Vec3 wi_cloth = DirectionGrid::to_direction(grid.chart_point(
      bin, (stratum % strata + rng.uniform()) / m, (stratum / strata + rng.uniform()) / m));
  Launch l;
  l.w0 = std::abs(wi_cloth.z);
  l.d = -cloth_to_world(wi_cloth);
  l.p = {slab.x0 + slab.px * rng.uniform(), wi_cloth.z > 0 ? slab.y1 : slab.y0,
         slab.z0 + slab.pz * rng.uniform()};
  return l;
}

Vec3 lattice_point(const RepeatSlab& slab, const Vec3& p, int m, int count) {
  const double golden = 0.5 * (1 + std::sqrt(5.0));
  const int64_t g = std::llround(count / golden);
  const double fx = (p.x - slab.x0) / slab.px + static_cast<double>(m) / count;
  const double fz = (p.z - slab.z0) / slab.pz + static_cast<double>((m * g) % count) / count;
  Vec3 q = p;
  q.x = slab.x0 + slab.px * (fx - std::floor(fx));
  q.z = slab.z0 + slab.pz * (fz - std::floor(fz));
  return q;
}

Strategies draw_strategies(bool mis, int groups, Rng& rng) {
  Strategies st;
  st.mis = mis;
  st.count = mis ? groups : 1;
  st.mean = groups;
  st.hero = mis ? std::min(groups - 1, static_cast<int>(rng.uniform() * groups)) : st.mean;
  return st;
}

Particle launched_particle(const Launch& l, int channels, const Strategies& st, bool proposal) {
  return {l.p,
          l.d,
          0,
          kNoFiber,
          false,
          std::vector<double>(channels, l.w0),
          std::vector<double>(st.count, 1.0),
          std::vector<double>(proposal ? channels : 0, l.w0)};
}

Boundaries boundaries_ahead(const RepeatSlab& slab, const Vec3& p, const Vec3& d) {
  Boundaries b;
  b.t_side = kInfinity;
  const double lo[2] = {slab.x0, slab.z0}, hi[2] = {slab.x0 + slab.px, slab.z0 + slab.pz};
  const double pc[2] = {p.x, p.z}, dc[2] = {d.x, d.z};
  for (int ax = 0; ax < 2; ++ax) {
    if (dc[ax] > 0 && (hi[ax] - pc[ax]) / dc[ax] < b.t_side)
      b.t_side = (hi[ax] - pc[ax]) / dc[ax], b.side = 2 * ax + 1;
    if (dc[ax] < 0 && (lo[ax] - pc[ax]) / dc[ax] < b.t_side)
      b.t_side = (lo[ax] - pc[ax]) / dc[ax], b.side = 2 * ax;
  }
  b.t_side = std::max(0.0, b.t_side);
  b.t_slab = d.y > 0 ? (slab.y1 - p.y) / d.y : d.y < 0 ? (slab.y0 - p.y) / d.y : kInfinity;
  return b;
}

Vec3 wrap_through_side(const RepeatSlab& slab, const Vec3& p, const Vec3& d, double t_side,
                       int side) {
  Vec3 q = p;
  q += t_side * d;
  if (side == 0) q.x += slab.px;
  if (side == 1) q.x -= slab.px;
  if (side == 2) q.z += slab.pz;
  if (side == 3) q.z -= slab.pz;
  return q;
}

SceneDescription tiled_geometry(const WovenSample& sample) {
  return *tiled_geometry(sample, no_progress());
}

std::optional<SceneDescription> tiled_geometry(const WovenSample& sample,
                                               const ProgressCallback& progress) {
  if (sample.fibers.curve_count() == 0 && sample.meshes.empty())
    throw Error("", "detail",
                "the ray-traced estimator needs the sample's geometry (fibers or yarn tubes); "
                "this sample has none");
  // Instanced: the neighbours of a yarn-detail repeat cost no memory of their own. Nor does the
  // repeat: the description holds the sample's own meshes, not the copies tiled_woven_description
  // makes (5e7 triangles of yarn tubes are 2.4 GB, seconds of copying that no poll could stop),
  // so it and any scene built from it must not outlive 'sample'. The placement is that of
  // tiled_woven_description, given empty meshes in their stead.
  WovenSample placement;
  placement.summary = sample.summary;
  placement.meshes.resize(sample.meshes.size());
  std::optional<SceneDescription> d = tiled_woven_description(
      sample.meshes.empty() ? sample : placement, 1, 1, "woven sample", true, progress);
  if (!d) return std::nullopt;
  for (size_t m = 0; m < sample.meshes.size(); ++m)
    d->meshes[m] = std::shared_ptr<const TriangleMesh>(std::shared_ptr<void>(), &sample.meshes[m]);
  MaterialBinding any;
  any.type = "lambert";
  any.field = "fabric estimator";
  d->default_material = any;
  return d;
}

int copy_index(int i, int k) {
  return 3 * (i + 1) + (k + 1);
}

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

Flight fly(const RenderScene& scene, const RepeatSlab& slab, int64_t curves, Particle& s,
           SurfaceHit* hit) {
  const Boundaries b = boundaries_ahead(slab, s.p, s.d);
  if (scene.intersect({s.p, s.d, std::min(b.t_side, b.t_slab)}, hit, s.ignore)) return Flight::hit;
  if (b.t_slab <= b.t_side) return Flight::left_slab;
  s.p = wrap_through_side(slab, s.p, s.d, b.t_side, b.side);
  s.ignore = fiber_after_wrap(s.ignore, b.side, curves);
  return Flight::wrapped;
}

bool passes_own_tube(const SurfaceHit& h, Particle& s) {
  const bool passes = s.in_tube && !h.on_fiber() && dot(s.d, h.ng) > 0;
  if (passes) s.p = h.spawn_origin(s.d);
  s.in_tube = false;
  return passes;
}

std::optional<Vec3> escape_direction(const RenderScene& scene, const RepeatSlab& slab,
                                     int64_t curves, Particle& s, int max_events) {
  for (int e = 0; e < max_events; ++e) {
    SurfaceHit h;
    const Flight f = fly(scene, slab, curves, s, &h);
    if (f == Flight::left_slab) return s.d;
    if (f == Flight::hit && !passes_own_tube(h, s)) return std::nullopt;
  }
  return std::nullopt;
}

Crossings crossings_of(const RenderScene& scene, const SurfaceHit& h, const Vec3& d,
                       const DirectionGrid& fiber_grid) {
  // The line meets a fiber at B' and would leave it at B''. A round fiber's B'' is where the line
  // leaves its cylinder. Yarn tubes that press on each other share surfaces, so a particle may
  // find itself inside one: then this hit is B'' and B' lies behind it. The scene never returns a
  // fiber hit from inside (RenderScene: a ray inside a fiber passes through it, as it passes
  // through its own fiber); such a hit grazed the surface (taken alone, without B'').
  Crossings x;
  const bool from_outside = dot(d, h.ng) < 0;
  x.pts[x.count++].hit = h;
  SurfaceHit other;
  if (h.on_fiber()) {
    if (from_outside && fiber_exit_point(scene, h, d, &other)) x.pts[x.count++].hit = other;
  } else if (find_crossing(scene, h, from_outside ? d : -d, &other)) {
    x.pts[x.count++].hit = other;
  }
  for (int q = 0; q < x.count; ++q) {
    FiberPoint& pt = x.pts[q];
    // On a yarn tube the table's frame is the facet's (its normal, the yarn's tangent in its
    // plane), not the interpolated shading normal: light arrives on a facet in proportion to its
    // cosine with the facet, and leaves drawn by the cosine with the frame's normal; the two
    // normals differing would make the transport non-reciprocal (Veach's thesis, 1997, ch. 5, on
    // shading normals).
    if (!pt.hit.on_fiber())
      pt.hit.shading = Frame::from_normal_tangent(pt.hit.ng, pt.hit.shading.s);
    pt.wi_local = pt.hit.shading.to_local(-d);
    pt.bin = fiber_grid.bin_of(pt.wi_local);
  }
  return x;
}

void albedo_sums(const FiberSampler& fs, const Strategies& st, const Crossings& x,
                 std::span<double> s_sum) {
  for (int j = 0; j < st.count; ++j) {
    s_sum[j] = 0;
    for (int q = 0; q < x.count; ++q)
      s_sum[j] +=
          fs.albedo_of(x.pts[q].bin, st.index(j)) + fs.lobe_albedo_of(x.pts[q].bin, st.index(j));
  }
}

// With the exact lobe, for light from wi in 'bin': the lobe's albedo rho_c(wi) and the rest's
// scale k_c(wi) per channel (FiberSampler::exact_lobe_split), computed once per point.
struct LobeSplit {
  std::array<double, kNumBands> rho{}, k{};
  size_t channels = 0;
  LobeSplit(const FiberSampler& fs, int bin, const Vec3& wi)
      : channels(static_cast<size_t>(fs.table->channels)) {
    fs.exact_lobe_split(bin, wi, {rho.data(), channels}, {k.data(), channels});
  }
  // The probability that strategy s draws the exit from the lobe: its channels' rho(wi) over
  // their albedo in 'bin' (1 where the rest has none).
  double share(const FiberSampler& fs, int s, int bin) const {
    const double total = fs.albedo_of(bin, s) + fs.lobe_albedo_of(bin, s);
    if (!(fs.albedo_of(bin, s) > 0)) return 1.0;
    return std::min(1.0, fs.group_mean({rho.data(), channels}, s) / total);
  }
};

std::optional<ScatterDraw> draw_scatter(const FiberSampler& fs, const Strategies& st,
                                        const Crossings& x, std::span<const double> s_sum,
                                        Rng& rng) {
  // With probability (A_h(q) / S_h) (f_h D_o / A_h(q)) = f_h D_o / S_h.
  const double s_hero = s_sum[st.hero_slot()];
  const double a_hero0 =
      fs.albedo_of(x.pts[0].bin, st.hero) + fs.lobe_albedo_of(x.pts[0].bin, st.hero);
  if (!(s_hero > 0)) return std::nullopt;
  ScatterDraw draw;
  draw.point = x.count == 2 && rng.uniform() * s_hero >= a_hero0 ? 1 : 0;
  const int bin = x.pts[draw.point].bin;
  if (fs.lobe) {
    const FiberPoint& q = x.pts[draw.point];
    if (rng.uniform() < LobeSplit(fs, q.bin, q.wi_local).share(fs, st.hero, q.bin)) {
      double pdf = 0;
      const Vec2 u{rng.uniform(), rng.uniform()};
      const auto wo = fs.lobe->sample(q.wi_local, u, &pdf);
      if (!wo) return std::nullopt;
      draw.wo_local = *wo;
      draw.exit_bin = fs.grid.bin_of(*wo);
      return draw;
    }
  }
  draw.exit_bin = static_cast<int>(fs.row(bin, st.hero).sample_discrete(rng.uniform()));
  draw.wo_local = fs.cosine_direction_in(draw.exit_bin, rng);
  return draw;
}

double weigh_scatter(const FiberSampler& fs, const TabulatedBsdfTable& fiber, const Strategies& st,
                     int bin, int exit_bin, std::span<const double> s_sum, Particle& s,
                     double* mean_pdf_out) {
  // Throughput f_c D_o over the strategies' mean probability of this step (D_o and the
  // within-cell density are common to all and cancel); densities kept relative to their mean so
  // that long paths neither underflow nor overflow.
  double mean_pdf = 0;
  for (int j = 0; j < st.count; ++j) {
    s.pdf[j] *= s_sum[j] > 0 ? fs.value(bin, exit_bin, st.index(j)) / s_sum[j] : 0.0;
    mean_pdf += s.pdf[j];
  }
  mean_pdf /= st.count;
  const int nc = fiber.channels;
  double before = 0, after = 0;
  for (int c = 0; c < nc; ++c) {
    before += s.w[c];
    s.w[c] *= fiber.at(bin, exit_bin, c) / mean_pdf;
    after += s.w[c];
  }
  // Under a proposal the path is drawn from it: fs's table.
  if (!s.wp.empty())
    for (int c = 0; c < nc; ++c) s.wp[c] *= fs.table->at(bin, exit_bin, c) / mean_pdf;
  for (double& x : s.pdf) x /= mean_pdf;
  if (mean_pdf_out) *mean_pdf_out = mean_pdf;
  return (before - after) / nc;
}

double weigh_scatter_lobe(const FiberSampler& fs, const TabulatedBsdfTable& rest,
                          const Strategies& st, const FiberPoint& pt, const ScatterDraw& draw,
                          std::span<const double> s_sum, Particle& s,
                          std::span<double> lobe_share) {
  const Vec3& wi = pt.wi_local;
  const Vec3& wo = draw.wo_local;
  const int bin = pt.bin, o = draw.exit_bin;
  const double cos_o = std::abs(wo.z);
  const double p_lobe = fs.lobe->pdf(wi, wo);
  // Strategy j: the point with T_j / S_j, then the lobe with share P_j (p_lobe) or the rest's
  // row (g_j D_o / A_j, then |cos| / D_o in the cell).
  const LobeSplit split(fs, bin, wi);
  double mean_pdf = 0;
  for (int j = 0; j < st.count; ++j) {
    const int k = st.index(j);
    const double a = fs.albedo_of(bin, k), total = a + fs.lobe_albedo_of(bin, k);
    const double share = split.share(fs, k, bin);
    const double rest_density = a > 0 ? fs.value(bin, o, k) * cos_o / a : 0.0;
    const double p =
        s_sum[j] > 0 ? total / s_sum[j] * (share * p_lobe + (1 - share) * rest_density) : 0.0;
    s.pdf[j] *= p;
    mean_pdf += s.pdf[j];
  }
  mean_pdf /= st.count;
  const int nc = rest.channels;
  const size_t n = static_cast<size_t>(nc);
  std::array<double, kNumBands> lobe_f{};
  fs.lobe->eval(wo, wi, {lobe_f.data(), n});
  double before = 0, after = 0;
  for (int c = 0; c < nc; ++c) {
    const size_t u = static_cast<size_t>(c);
    before += s.w[c];
    const double f = rest.at(bin, o, c) * split.k[u] + lobe_f[u];
    s.w[c] *= f * cos_o / mean_pdf;
    after += s.w[c];
    if (!lobe_share.empty()) lobe_share[u] = f > 0 ? lobe_f[u] / f : 0.0;
  }
  for (double& x : s.pdf) x /= mean_pdf;
  return (before - after) / nc;
}

void scale_as_round_fiber(const LineAlbedo& table, double axial, std::span<const int> bins,
                          std::vector<double>& w) {
  for (size_t c = 0; c < w.size(); ++c) {
    const int ch = static_cast<int>(c);
    double s_sum = 0;
    for (int bin : bins) s_sum += table.point(bin, ch);
    if (s_sum > 0) w[c] *= table.line(axial, ch) / s_sum;
  }
}

double weigh_as_round_fiber(const LineAlbedo& traced, const LineAlbedo* proposal,
                            const Crossings& x, const Vec3& d, Particle& s) {
  const double axial = dot(d, x.pts[0].hit.shading.s);
  const int bins[2] = {x.pts[0].bin, x.pts[1].bin};
  const std::span<const int> points(bins, static_cast<size_t>(x.count));
  const double before = mean_weight(s.w);
  scale_as_round_fiber(traced, axial, points, s.w);
  if (proposal && !s.wp.empty()) scale_as_round_fiber(*proposal, axial, points, s.wp);
  return before - mean_weight(s.w);
}

void leave_fiber(const SurfaceHit& hit, const Vec3& wo_local, Particle& s) {
  s.d = normalize(hit.shading.to_world(wo_local));
  s.p = hit.spawn_origin(s.d);
  s.ignore = hit.fiber;                                 // light leaves a fiber through the fiber
  s.in_tube = !hit.on_fiber() && dot(s.d, hit.ng) < 0;  // into its own yarn tube
}

FabricBinBooks& Tally::books_of(int bin) {
  if (books.empty() || books.back().first != bin) books.emplace_back(bin, FabricBinBooks{});
  return books.back().second;
}

uint64_t exit_cell(const DirectionGrid& grid, int bin, const Vec3& d) {
  const int exit_bin = grid.bin_of(world_to_cloth(d));
  return static_cast<uint64_t>(bin) * grid.bins() + exit_bin;
}

void tally_exit(Tally& tally, size_t first_exit, uint64_t cell, std::span<const double> w) {
  size_t e = first_exit;
  while (e < tally.exits.size() && tally.exits[e].cell != cell) ++e;
  if (e < tally.exits.size()) {
    for (size_t c = 0; c < w.size(); ++c) tally.weights[tally.exits[e].first + c] += w[c];
  } else {
    tally.exits.push_back({cell, static_cast<uint32_t>(tally.weights.size())});
    tally.weights.insert(tally.weights.end(), w.begin(), w.end());
  }
}

Steering steering_of(const Particle& s) {
  // Russian roulette on the largest channel weight (on their mean before spectral MIS, which let
  // the dominant channel's weights grow where the mean fell).
  Steering st;
  st.mean_w = mean_weight(s.w);
  for (double x : s.wp.empty() ? s.w : s.wp) st.mean_p += x, st.max_w = std::max(st.max_w, x);
  st.mean_p /= static_cast<double>(s.w.size());
  return st;
}

bool survives_roulette(double steer, double threshold, double mean_w, Particle& s,
                       FabricBinBooks& books, Rng& rng, double* divided_by) {
  if (!(steer < threshold)) return true;
  const double survive = steer / (threshold);
  if (rng.uniform() < survive) {
    if (divided_by) *divided_by = survive;
    for (double& x : s.w) x /= survive;
    for (double& x : s.wp) x /= survive;
    books.roulette_net -= mean_w / survive - mean_w;
    return true;
  }
  books.roulette_net += mean_w;
  ++books.roulette_kills;
  return false;
}

int split_count(double max_w, double split_threshold, int copies_left) {
  return static_cast<int>(std::min<double>(
      {double(kMaxSplit), std::ceil(max_w / split_threshold), double(copies_left + 1)}));
}

void split(Particle& s, int n, std::vector<Particle>& pending) {
  for (double& x : s.w) x /= n;
  for (double& x : s.wp) x /= n;
  for (int copy = 1; copy < n; ++copy) pending.push_back(s);
}

}  // namespace weft::raytrace
