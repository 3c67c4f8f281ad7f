#include "weft/materials/fabric/fiber_bake.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/sphere_mapping.h"
#include "weft/materials/fresnel.h"

namespace weft {
namespace {

// The frame of the surface point at angle phi around the axis (x): n = (0, cos, sin),
// t = x, b = n x t = (0, sin, -cos). Local coordinates are (t, b, n).
struct FiberPointFrame {
  Vec3 n, b;
  explicit FiberPointFrame(double phi)
      : n{0, std::cos(phi), std::sin(phi)}, b{0, std::sin(phi), -std::cos(phi)} {}
  Vec3 to_local(const Vec3& v) const { return {v.x, dot(v, b), dot(v, n)}; }
  Vec3 to_world(const Vec3& v) const { return Vec3{v.x, 0, 0} + v.y * b + v.z * n; }
};

void validate(const FiberGeometry& g, const FiberBakeSettings& s) {
  if (!(g.radius_um > 0) || !std::isfinite(g.radius_um))
    throw Error("", "radius_um", "fiber radius must be positive and finite");
  if (!(g.n_fiber >= 1) || !std::isfinite(g.n_fiber))
    throw Error("", "n_fiber", "fiber refractive index must be finite and >= 1");
  if (!(g.n_outside >= 1) || !std::isfinite(g.n_outside))
    throw Error("", "n_outside", "outside refractive index must be finite and >= 1");
  if (s.resolution < 2 || s.resolution > 64)
    throw Error("", "resolution", "table resolution must lie in [2, 64]");
  if (s.photons == 0) throw Error("", "photons", "need at least one photon");
  if (s.photons_per_task == 0) throw Error("", "photons_per_task", "must be positive");
}

// Runs 'count' tasks in fixed chunks so that at most 'chunk' task tallies live at once, adds each
// task's tally into 'total' in task order (bit-identical at any thread count), and reports
// progress between chunks. Returns the number of tasks completed (< count if cancelled).
template <class Tally, class RunTask, class Merge>
uint64_t run_tasks_ordered(uint64_t count, int threads, uint64_t units_per_task,
                           uint64_t total_units, std::string_view stage,
                           const ProgressCallback& progress, const RunTask& run_task,
                           const Merge& merge) {
  const uint64_t chunk = 32;
  uint64_t done = 0;
  while (done < count) {
    const uint64_t n = std::min(chunk, count - done);
    std::vector<Tally> tallies(n);
    parallel_for(n, threads, [&](uint64_t k) { run_task(done + k, tallies[k]); });
    for (uint64_t k = 0; k < n; ++k) merge(tallies[k]);
    done += n;
    const uint64_t units = std::min(total_units, done * units_per_task);
    if (progress && !progress({stage, units, total_units})) break;
  }
  return done;
}

// Energy books of a batch of photons (weights, not yet divided by the flux launched).
struct EnergyTally {
  double launched = 0, exited = 0, surface = 0, absorbed = 0, roulette_net = 0, lost = 0,
         excess = 0;
  uint64_t photons = 0, events = 0;

  void add_trace(const FiberTraceResult& r) {
    events += r.scattering_events;
    absorbed += r.absorbed_weight;
    roulette_net += r.roulette_net;
    lost += r.lost_weight;
  }
  EnergyTally& operator+=(const EnergyTally& o) {
    launched += o.launched, exited += o.exited, surface += o.surface, absorbed += o.absorbed;
    roulette_net += o.roulette_net, lost += o.lost, excess += o.excess;
    photons += o.photons, events += o.events;
    return *this;
  }
  void fill(FiberBandTable& t) const {
    const double inv = launched > 0 ? 1 / launched : 0;
    t.photons = photons;
    t.scattering_events = events;
    t.exit_fraction = exited * inv;
    t.surface_fraction = surface * inv;
    t.absorbed_fraction = absorbed * inv;
    t.roulette_net = roulette_net * inv;
    t.lost_fraction = lost * inv;
    t.surface_sampling_excess = excess * inv;
  }
};

struct DirectTally {
  // Exits in the order they happened: (cell index, weight). Sparse, because a task's photons
  // touch few of the R^4 cells; merged in task order, so sums are the same at any thread count.
  std::vector<std::pair<uint64_t, double>> exits;
  std::vector<std::pair<uint64_t, double>> far_field;  // likewise, if asked
  EnergyTally energy;
};

}  // namespace

int direction_bin(const Vec3& d, int resolution) {
  const Vec2 p = equal_area_sphere_to_square(d);
  const int ix = std::min(resolution - 1, static_cast<int>(p.x * resolution));
  const int iy = std::min(resolution - 1, static_cast<int>(p.y * resolution));
  return iy * resolution + ix;
}

namespace {

// Integral of |cos theta| over the preimage of [a,b] x [c,d] (0 <= a < b, 0 <= c < d) in the
// octahedral square coordinates u', v' in [-1, 1], where d omega = pi du' dv'. On this map
// |cos theta| depends on rho = u' + v' only (1 - rho^2 on the upper half, 1 - (2 - rho)^2 on the
// lower), so the integral is one-dimensional: int |cos|(rho) m(rho) d rho with m(rho) the length
// of the cut u' + v' = rho through the rectangle. Both factors are polynomial between the
// breakpoints, so 3-point Gauss-Legendre per piece is exact.
double cos_integral_quadrant_rect(double a, double b, double c, double d) {
  double breaks[] = {a + c, a + d, b + c, b + d, 1.0};
  std::sort(std::begin(breaks), std::end(breaks));
  const double lo = a + c, hi = b + d;
  auto m = [&](double rho) { return std::max(0.0, std::min(b, rho - c) - std::max(a, rho - d)); };
  auto abs_cos = [](double rho) { return rho <= 1 ? 1 - rho * rho : 1 - (2 - rho) * (2 - rho); };
  const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double sum = 0;
  for (int k = 0; k + 1 < 5; ++k) {
    const double p0 = std::clamp(breaks[k], lo, hi), p1 = std::clamp(breaks[k + 1], lo, hi);
    if (!(p1 > p0)) continue;
    const double mid = 0.5 * (p0 + p1), half = 0.5 * (p1 - p0);
    for (int q = 0; q < 3; ++q)
      sum += w[q] * half * abs_cos(mid + half * x[q]) * m(mid + half * x[q]);
  }
  return kPi * sum;
}

}  // namespace

std::vector<double> cosine_weighted_bin_areas(int resolution) {
  std::vector<double> out(static_cast<size_t>(resolution) * resolution, 0.0);
  for (int iy = 0; iy < resolution; ++iy)
    for (int ix = 0; ix < resolution; ++ix) {
      // The bin in u', v', split at the axes so that each piece lies in one quadrant.
      const double u0 = 2.0 * ix / resolution - 1, u1 = 2.0 * (ix + 1) / resolution - 1;
      const double v0 = 2.0 * iy / resolution - 1, v1 = 2.0 * (iy + 1) / resolution - 1;
      double total = 0;
      for (auto [ua, ub] : {std::pair{u0, std::min(u1, 0.0)}, std::pair{std::max(u0, 0.0), u1}})
        for (auto [va, vb] : {std::pair{v0, std::min(v1, 0.0)}, std::pair{std::max(v0, 0.0), v1}}) {
          if (!(ub > ua) || !(vb > va)) continue;
          // Reflect into the first quadrant.
          const double a = std::min(std::abs(ua), std::abs(ub)),
                       b = std::max(std::abs(ua), std::abs(ub));
          const double c = std::min(std::abs(va), std::abs(vb)),
                       d = std::max(std::abs(va), std::abs(vb));
          total += cos_integral_quadrant_rect(a, b, c, d);
        }
      out[static_cast<size_t>(iy) * resolution + ix] = total;
    }
  return out;
}

double fiber_table_energy(const FiberBandTable& table) {
  double sum = 0;
  for (double v : table.weighted_sum) sum += v;
  return sum;
}

namespace {

FiberBandTable finish_table(int resolution, std::vector<double> weighted_sum) {
  FiberBandTable t;
  t.resolution = resolution;
  const int cells = resolution * resolution;
  const auto d = cosine_weighted_bin_areas(resolution);
  t.f.assign(weighted_sum.size(), 0.0);
  for (int i = 0; i < cells; ++i)
    for (int o = 0; o < cells; ++o)
      t.f[static_cast<size_t>(i) * cells + o] =
          weighted_sum[static_cast<size_t>(i) * cells + o] / (d[i] * d[o]);
  t.weighted_sum = std::move(weighted_sum);
  return t;
}

// Light hits the surface at 'point' (normal n_point, local frame 'frame') from world direction
// 'omega' (towards the light). Emits the surface-reflected exit and traces the refracted part.
// 'w0' is the photon's flux weight.
template <class Frame_, class Sink>
void hit_fiber(const FiberGeometry& g, const FiberSurfaceModel& surface,
               const FiberInteriorTracer& tracer, const Frame_& frame, const Vec3& point,
               const Vec3& omega, double w0, Rng& rng, const Sink& sink, EnergyTally& energy) {
  energy.launched += w0;
  ++energy.photons;
  const Vec3 omega_local = frame.to_local(omega);
  const double cos_a = omega_local.z;
  if (!(cos_a > 0)) {  // a grazing edge ray (measure zero): book it, never drop it
    energy.lost += w0;
    return;
  }
  double sampled_surface = 0;
  // Surface lobe: one sampled reflected direction with weight f cos / pdf (expectation = albedo).
  Vec3 w_out;
  double weight = 0;
  const Vec2 u{rng.uniform(), rng.uniform()};
  const double u_lobe = rng.uniform();
  if (surface.sample && surface.sample(omega_local, u, u_lobe, &w_out, &weight) && weight > 0) {
    const FiberExit e{point, frame.to_world(w_out), w0 * weight};
    sampled_surface = e.weight;
    energy.surface += e.weight;
    sink(e);
  }
  // The rest enters, refracted at the macroscopic (smooth) normal.
  const double albedo = surface.albedo ? surface.albedo(cos_a) : 0.0;
  energy.excess += sampled_surface - w0 * albedo;
  const double w_in = w0 * (1 - albedo);
  if (!(w_in > 0)) return;
  Vec3 d;
  if (!refract(-omega, frame.n, g.n_outside, g.n_fiber, &d)) {  // impossible from outside
    energy.lost += w_in;
    return;
  }
  energy.add_trace(tracer(point, normalize(d), w_in, rng, sink));
}

}  // namespace

FiberBandTable bake_fiber_band_direct(const FiberGeometry& g, const FiberSurfaceModel& surface,
                                      const FiberInteriorTracer& tracer, const FiberBakeSettings& s,
                                      const ProgressCallback& progress) {
  validate(g, s);
  const int R = s.resolution;
  const size_t cells = static_cast<size_t>(R) * R;
  const uint64_t tasks = (s.photons + s.photons_per_task - 1) / s.photons_per_task;
  std::vector<double> total(cells * cells, 0.0);
  EnergyTally energy;
  const bool far_field = s.far_field_s_bins > 0 && s.far_field_psi_bins > 0;
  const int ffs = s.far_field_s_bins, ffp = s.far_field_psi_bins;
  std::vector<double> far_total(far_field ? static_cast<size_t>(ffs) * ffs * ffp : 0, 0.0);

  auto run_task = [&](uint64_t task, DirectTally& tally) {
    tally.exits.reserve(2 * s.photons_per_task);
    Rng rng(s.seed, task);
    const uint64_t first = task * s.photons_per_task;
    const uint64_t n = std::min(s.photons_per_task, s.photons - first);
    for (uint64_t k = 0; k < n; ++k) {
      // Axial cosine s of the light direction with density (2/pi) sqrt(1 - s^2) (the fiber's
      // projected width), via the x coordinate of a uniform point in the unit disk.
      const double r = std::sqrt(rng.uniform());
      const double s_axial = r * std::cos(2 * kPi * rng.uniform());
      const double c = safe_sqrt(1 - s_axial * s_axial);
      const Vec3 omega{s_axial, 0, c};  // towards the light, which is above (+z)
      // Impact parameter uniform across the projected width: entry angle phi_A on the lit half.
      const double p = 2 * rng.uniform() - 1;  // in units of R
      const double phi_a = std::atan2(safe_sqrt(1 - p * p), p);
      const FiberPointFrame frame_a(phi_a);
      const Vec3 point_a = g.radius_um * frame_a.n;
      auto sink = [&](const FiberExit& e) {
        const double phi_b = std::atan2(e.position.z, e.position.y);
        const FiberPointFrame frame_b(phi_b);
        const int i = direction_bin(frame_b.to_local(omega), R);
        const int o = direction_bin(frame_b.to_local(e.direction), R);
        tally.exits.emplace_back(static_cast<uint64_t>(i) * cells + o, e.weight);
        tally.energy.exited += e.weight;
        if (far_field) {
          const int a = std::clamp(static_cast<int>((omega.x + 1) / 2 * ffs), 0, ffs - 1);
          const int b = std::clamp(static_cast<int>((e.direction.x + 1) / 2 * ffs), 0, ffs - 1);
          double dpsi = std::atan2(e.direction.z, e.direction.y) - std::atan2(omega.z, omega.y);
          dpsi -= 2 * kPi * std::floor((dpsi + kPi) / (2 * kPi));
          const int c = std::clamp(static_cast<int>((dpsi + kPi) / (2 * kPi) * ffp), 0, ffp - 1);
          tally.far_field.emplace_back((static_cast<uint64_t>(a) * ffs + b) * ffp + c, e.weight);
        }
      };
      hit_fiber(g, surface, tracer, frame_a, point_a, omega, 1.0, rng, sink, tally.energy);
    }
  };
  auto merge = [&](const DirectTally& t) {
    for (const auto& [k, w] : t.exits) total[k] += w;
    for (const auto& [k, w] : t.far_field) far_total[k] += w;
    energy += t.energy;
  };
  const uint64_t done = run_tasks_ordered<DirectTally>(
      tasks, s.threads, s.photons_per_task, s.photons, "photons", progress, run_task, merge);
  // Each photon stands for pi / N of the integral (see docs/fiber-bsdf.md).
  const double scale = energy.photons > 0 ? kPi / static_cast<double>(energy.photons) : 0.0;
  for (auto& v : total) v *= scale;
  for (auto& v : far_total) v *= scale;
  FiberBandTable t = finish_table(R, std::move(total));
  t.far_field = std::move(far_total);
  energy.fill(t);
  t.cancelled = done < tasks;
  return t;
}

FiberBandTable bake_fiber_band_bssrdf(const FiberGeometry& g, const FiberSurfaceModel& surface,
                                      const FiberInteriorTracer& tracer, const FiberBakeSettings& s,
                                      const BssrdfGrid& grid, const ProgressCallback& progress) {
  validate(g, s);
  if (grid.u_bins < 2 || grid.u_bins % 2 != 0 || grid.incident_s_bins < 1 ||
      grid.incident_psi_bins < 1 || grid.cell_quadrature < 1)
    throw Error("", "bssrdf_grid", "grid sizes must be positive and u_bins even");
  const int R = s.resolution;
  const size_t cells = static_cast<size_t>(R) * R;
  const int nu = grid.u_bins, ns = grid.incident_s_bins, npsi = grid.incident_psi_bins;
  const size_t incident_bins = static_cast<size_t>(ns) * npsi;
  // T[a][j][o]: exit weight by incident bin a, angular offset bin j, exit direction bin o.
  const size_t t_size = incident_bins * nu * cells;
  if (t_size > (size_t{1} << 27))  // 1 GiB of doubles
    throw Error(
        "", "bssrdf_grid",
        "the BSSRDF table (incident bins x offsets x exit bins = " + std::to_string(t_size) +
            " values) is too large for this resolution; use the direct route or a coarser grid");
  const uint64_t tasks = (s.photons + s.photons_per_task - 1) / s.photons_per_task;
  const double du = 2 * kPi / nu;
  // A sits at the top of the fiber (phi = pi/2): its frame is the identity.
  const FiberPointFrame frame_a(kPi / 2);
  const Vec3 point_a = g.radius_um * frame_a.n;

  struct Tally {
    std::vector<std::pair<uint64_t, double>> exits;  // (T index, weight), in order
    std::vector<double> f_in;
    EnergyTally energy;
  };
  std::vector<double> t_total(t_size, 0.0), f_in_total(incident_bins, 0.0);
  EnergyTally energy;

  auto run_task = [&](uint64_t task, Tally& tally) {
    tally.exits.reserve(2 * s.photons_per_task);
    tally.f_in.assign(incident_bins, 0.0);
    Rng rng(s.seed, task);
    const uint64_t first = task * s.photons_per_task;
    const uint64_t n = std::min(s.photons_per_task, s.photons - first);
    for (uint64_t k = 0; k < n; ++k) {
      // Incident bins in turn (stratified); direction uniform in (s, psi) inside the bin, which is
      // uniform in solid angle; the flux it carries is proportional to cos theta_A.
      const size_t a = (first + k) % incident_bins;
      const int is = static_cast<int>(a / npsi), ip = static_cast<int>(a % npsi);
      const double s_axial = -1 + 2 * (is + rng.uniform()) / ns;
      const double psi = -kPi / 2 + kPi * (ip + rng.uniform()) / npsi;
      const double c = safe_sqrt(1 - s_axial * s_axial);
      const Vec3 omega_local{s_axial, c * std::sin(psi), c * std::cos(psi)};
      const Vec3 omega = frame_a.to_world(omega_local);
      const double w0 = omega_local.z;
      tally.f_in[a] += w0;
      auto sink = [&](const FiberExit& e) {
        const double phi_b = std::atan2(e.position.z, e.position.y);
        double offset = phi_b - kPi / 2;  // angular offset of B from A, wrapped to [-pi, pi)
        offset -= 2 * kPi * std::floor((offset + kPi) / (2 * kPi));
        // Bin j is centred at offset -pi + j du, so offset 0 (surface reflection) is a centre.
        const int j = static_cast<int>(std::floor((offset + kPi) / du + 0.5)) % nu;
        const FiberPointFrame frame_b(phi_b);
        const int o = direction_bin(frame_b.to_local(e.direction), R);
        tally.exits.emplace_back((a * nu + j) * cells + o, e.weight);
        tally.energy.exited += e.weight;
      };
      hit_fiber(g, surface, tracer, frame_a, point_a, omega, w0, rng, sink, tally.energy);
    }
  };
  auto merge = [&](const Tally& t) {
    for (const auto& [k, w] : t.exits) t_total[k] += w;
    for (size_t k = 0; k < incident_bins; ++k) f_in_total[k] += t.f_in[k];
    energy += t.energy;
  };
  const uint64_t done = run_tasks_ordered<Tally>(tasks, s.threads, s.photons_per_task, s.photons,
                                                 "photons", progress, run_task, merge);

  // T = F_out / F_in per incident bin: the BSSRDF of the paper times the exit cell's geometry
  // (Delta omega_out B_i cos theta_out), summed over the axial offset.
  for (size_t a = 0; a < incident_bins; ++a) {
    const double inv = f_in_total[a] > 0 ? 1 / f_in_total[a] : 0;
    for (size_t k = 0; k < static_cast<size_t>(nu) * cells; ++k) t_total[a * nu * cells + k] *= inv;
  }

  // BRDF of cell B: the paper's sum over lit cells A_i at offsets j, integrated over the incident
  // table bin by a cq x cq midpoint rule. B sits at the top; A_j at phi = pi/2 - offset_j.
  std::vector<FiberPointFrame> frames_aj;
  for (int j = 0; j < nu; ++j) frames_aj.emplace_back(kPi / 2 - (-kPi + j * du));
  const int cq = grid.cell_quadrature;
  const double point_solid_angle = 4 * kPi / (static_cast<double>(R) * R) / (cq * cq);
  std::vector<double> weighted(cells * cells, 0.0);
  parallel_for(cells, s.threads, [&](uint64_t i) {
    const int ix = static_cast<int>(i % R), iy = static_cast<int>(i / R);
    double* row = &weighted[i * cells];
    for (int qa = 0; qa < cq; ++qa)
      for (int qb = 0; qb < cq; ++qb) {
        const Vec3 omega = equal_area_square_to_sphere(
            {(ix + (qb + 0.5) / cq) / R, (iy + (qa + 0.5) / cq) / R});  // world = B's frame
        for (int j = 0; j < nu; ++j) {
          const Vec3 wa = frames_aj[j].to_local(omega);
          if (!(wa.z > 0)) continue;
          // Bilinear interpolation between incident-bin centres in (s, psi): the BSSRDF varies
          // quickly with the incident direction (the surface lobe moves with it), and a
          // nearest-bin lookup would smear it by a bin width.
          const double psi = std::atan2(wa.y, wa.z);
          const double xs = std::clamp((wa.x + 1) / 2 * ns - 0.5, 0.0, ns - 1.0);
          const double xp = std::clamp((psi + kPi / 2) / kPi * npsi - 0.5, 0.0, npsi - 1.0);
          const int s0 = std::min(static_cast<int>(xs), ns - 1),
                    p0 = std::min(static_cast<int>(xp), npsi - 1);
          const int s1 = std::min(s0 + 1, ns - 1), p1 = std::min(p0 + 1, npsi - 1);
          const double fs = xs - s0, fp = xp - p0;
          const double w = point_solid_angle * wa.z;
          const size_t corner[4] = {
              static_cast<size_t>(s0) * npsi + p0, static_cast<size_t>(s0) * npsi + p1,
              static_cast<size_t>(s1) * npsi + p0, static_cast<size_t>(s1) * npsi + p1};
          const double cw[4] = {(1 - fs) * (1 - fp), (1 - fs) * fp, fs * (1 - fp), fs * fp};
          for (int c = 0; c < 4; ++c) {
            if (cw[c] == 0) continue;
            const double* t = &t_total[(corner[c] * nu + j) * cells];
            const double wc = w * cw[c];
            for (size_t o = 0; o < cells; ++o) row[o] += wc * t[o];
          }
        }
      }
  });
  FiberBandTable t = finish_table(R, std::move(weighted));
  energy.fill(t);
  t.cancelled = done < tasks;
  return t;
}

}  // namespace weft
