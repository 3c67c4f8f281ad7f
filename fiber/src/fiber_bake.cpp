#include "weft/fiber/fiber_bake.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/sobol.h"
#include "weft/fiber/bssrdf.h"
#include "weft/fiber/transport_batch.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

void validate(const FiberBandPhysics& fiber, const FiberBakeSettings& s) {
  fiber.validate();
  if (s.resolution < 2 || s.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "table resolution must lie in [2, " +
                    std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (s.photons == 0) throw Error("", "photons", "need at least one photon");
  if (s.photons_per_task == 0) throw Error("", "photons_per_task", "must be positive");
  if (s.entry != FiberEntrySampling::kRandom && s.entry != FiberEntrySampling::kStratified)
    throw Error("", "entry", "must be random or stratified");
  // A task's Sobol' points are indexed by 32 bits (photon times surface samples).
  if (s.entry == FiberEntrySampling::kStratified &&
      s.photons_per_task * static_cast<uint64_t>(std::max(1, fiber.surface.samples)) >
          (uint64_t{1} << 32))
    throw Error("", "photons_per_task", "too many photons per task for a stratified entry");
}

TaskBatch batch_of(const FiberBakeSettings& s, const ProgressCallback& progress) {
  TaskBatch b = photon_batch({});
  b.items = s.photons, b.seed = s.seed, b.threads = s.threads;
  b.items_per_task = s.photons_per_task, b.progress = progress;
  return b;
}

// The table from the sums of f |cos_i| |cos_o| per cell pair, and the books' fractions.
FiberBandTable finish_table(int resolution, std::vector<double> weighted_sum,
                            const PhotonTally& books, bool cancelled) {
  FiberBandTable t;
  t.resolution = resolution;
  t.f = TabulatedBsdfTable::averages_from_weighted_sums(resolution, weighted_sum);
  t.weighted_sum = std::move(weighted_sum);
  const double inv = books.launched > 0 ? 1 / books.launched : 0;
  t.photons = books.photons;
  t.scattering_events = books.scatterings;
  t.exit_fraction = (books.specular + books.exited) * inv;
  t.surface_fraction = books.specular * inv;
  t.absorbed_fraction = books.absorbed * inv;
  t.roulette_net = (books.roulette_loss - books.roulette_gain) * inv;
  t.lost_fraction = books.lost * inv;
  t.surface_sampling_excess = books.specular_excess * inv;
  t.expected_exit_excess = books.expected_exit_excess * inv;
  t.cancelled = cancelled;
  return t;
}

// A photon's entry for the direct route (the uniforms of bake_fiber_band_direct's photon k of a
// task): from the task's Sobol' points when stratified (dimensions 0-2 the entry, 3-5 the surface
// lobe's samples k * samples + j), else from rng in the order the random entry always drew them.
struct EntryDraws {
  double u[3];               // light direction (two), impact parameter
  std::vector<double> lobe;  // 3 per surface sample; empty: enter_fiber draws them from rng
};
void draw_entry(const ScrambledSobol* sobol, uint64_t k, int lobe_samples, Rng& rng,
                EntryDraws& e) {
  if (!sobol) {
    for (double& u : e.u) u = rng.uniform();
    return;
  }
  const auto index = static_cast<uint32_t>(k);
  for (int d = 0; d < 3; ++d) e.u[d] = sobol->sample(index, d);
  e.lobe.resize(3 * static_cast<size_t>(lobe_samples));
  for (int j = 0; j < lobe_samples; ++j)
    for (int d = 0; d < 3; ++d)
      e.lobe[3 * j + d] = sobol->sample(index * static_cast<uint32_t>(lobe_samples) + j, 3 + d);
}

struct DirectTally {
  // Exits in the order they happened: (cell index, weight). Sparse, because a task's photons
  // touch few of the R^4 cells; merged in task order, so sums are the same at any thread count.
  std::vector<std::pair<uint64_t, double>> exits;
  std::vector<std::pair<uint64_t, double>> far_field;  // likewise, if asked
  PhotonTally books;
};

}  // namespace

const char* fiber_entry_sampling_name(FiberEntrySampling e) {
  return name_of(kFiberEntrySamplings, e);
}

FiberEntrySampling parse_fiber_entry_sampling(const std::string& name, const std::string& field) {
  return value_of(kFiberEntrySamplings, name, "", field);
}

double fiber_table_energy(const FiberBandTable& table) {
  double sum = 0;
  for (double v : table.weighted_sum) sum += v;
  return sum;
}

std::vector<double> fold_fiber_mirror_symmetry(int resolution, const std::vector<double>& v) {
  const DirectionGrid grid{resolution};
  const size_t cells = static_cast<size_t>(grid.bins());
  if (v.size() != cells * cells) throw Error("", "cells", "the sums do not fit the resolution");
  // The bins' images under no flip, the axis flip, the binormal flip and both.
  std::vector<std::array<int, 4>> image(cells);
  for (size_t b = 0; b < cells; ++b) {
    const int k = static_cast<int>(b), t = grid.mirrored_bin(k, 0), n = grid.mirrored_bin(k, 1);
    image[b] = {k, t, n, grid.mirrored_bin(t, 1)};
  }
  std::vector<double> folded(v.size());
  for (size_t i = 0; i < cells; ++i)
    for (size_t o = 0; o < cells; ++o) {
      double sum = 0;
      for (int m = 0; m < 4; ++m) sum += v[static_cast<size_t>(image[i][m]) * cells + image[o][m]];
      folded[i * cells + o] = 0.25 * sum;
    }
  return folded;
}

FiberBandTable bake_fiber_band_direct(const FiberBandPhysics& fiber, const FiberBakeSettings& s,
                                      const ProgressCallback& progress) {
  validate(fiber, s);
  const DirectionGrid grid{s.resolution};
  const size_t cells = static_cast<size_t>(grid.bins());
  std::vector<double> total(cells * cells, 0.0);
  PhotonTally books;
  const bool far_field = s.far_field_s_bins > 0 && s.far_field_psi_bins > 0;
  const int ffs = s.far_field_s_bins, ffp = s.far_field_psi_bins;
  std::vector<double> far_total(far_field ? static_cast<size_t>(ffs) * ffs * ffp : 0, 0.0);
  const bool stratified = s.entry == FiberEntrySampling::kStratified;
  // The rough dielectric boundary draws its walk from rng, not lobe samples.
  const int lobe_samples = fiber.boundary ? 0 : std::max(1, fiber.surface.samples);

  const TaskBatchStatus status = run_batch<DirectTally>(
      batch_of(s, progress),
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, DirectTally& tally) {
        tally.exits.reserve(2 * count);
        Vec3 omega;  // the light direction of the photon in flight
        const ExitSink sink = [&](const ExitEvent& e) {
          const Frame frame_b =
              CylinderGeometry::cylinder_frame(std::atan2(e.position.z, e.position.y));
          const int i = grid.bin_of(frame_b.to_local(omega));
          const int o = grid.bin_of(frame_b.to_local(e.direction));
          tally.exits.emplace_back(static_cast<uint64_t>(i) * cells + o, e.weight);
          if (far_field) {
            const int a = std::clamp(static_cast<int>((omega.x + 1) / 2 * ffs), 0, ffs - 1);
            const int b = std::clamp(static_cast<int>((e.direction.x + 1) / 2 * ffs), 0, ffs - 1);
            double dpsi = std::atan2(e.direction.z, e.direction.y) - std::atan2(omega.z, omega.y);
            dpsi -= 2 * kPi * std::floor((dpsi + kPi) / (2 * kPi));
            const int c = std::clamp(static_cast<int>((dpsi + kPi) / (2 * kPi) * ffp), 0, ffp - 1);
            tally.far_field.emplace_back((static_cast<uint64_t>(a) * ffs + b) * ffp + c, e.weight);
          }
        };
        // Stratified: the task's own Sobol' points, drawn from its stream (any thread count).
        std::optional<ScrambledSobol> sobol;
        if (stratified) sobol.emplace(rng);
        EntryDraws e;
        for (uint64_t k = 0; k < count; ++k) {
          draw_entry(sobol ? &*sobol : nullptr, k, lobe_samples, rng, e);
          // Axial cosine s of the light direction with density (2/pi) sqrt(1 - s^2) (the fiber's
          // projected width), via the x coordinate of a uniform point in the unit disk.
          const double r = std::sqrt(e.u[0]);
          const double s_axial = r * std::cos(2 * kPi * e.u[1]);
          const double c = safe_sqrt(1 - s_axial * s_axial);
          omega = {s_axial, 0, c};  // towards the light, which is above (+z)
          // Impact parameter uniform across the projected width: entry angle phi_A on the lit
          // half.
          const double p = 2 * e.u[2] - 1;  // in units of R
          const double phi_a = std::atan2(safe_sqrt(1 - p * p), p);
          enter_fiber(fiber, phi_a, omega, 1.0, rng, s.book_surface ? sink : ExitSink{}, sink,
                      tally.books, e.lobe);
        }
      },
      [&](const DirectTally& t) {
        for (const auto& [k, w] : t.exits) total[k] += w;
        for (const auto& [k, w] : t.far_field) far_total[k] += w;
        books += t.books;
      });
  // Each photon stands for pi / N of the integral (see docs/fiber-bsdf.md).
  const double scale = books.photons > 0 ? kPi / static_cast<double>(books.photons) : 0.0;
  for (auto& v : total) v *= scale;
  for (auto& v : far_total) v *= scale;
  FiberBandTable t = finish_table(s.resolution, std::move(total), books, status.cancelled);
  t.far_field = std::move(far_total);
  return t;
}

FiberBandTable bake_fiber_band_bssrdf(const FiberBandPhysics& fiber, const FiberBakeSettings& s,
                                      const BssrdfRouteSettings& route,
                                      const ProgressCallback& progress) {
  validate(fiber, s);
  if (route.u_bins < 2 || route.u_bins % 2 != 0 || route.incident_s_bins < 1 ||
      route.incident_psi_bins < 1 || route.cell_quadrature < 1)
    throw Error("", "bssrdf_grid", "grid sizes must be positive and u_bins even");
  const int R = s.resolution;
  const DirectionGrid table_grid{R};
  const size_t cells = static_cast<size_t>(table_grid.bins());
  const int nu = route.u_bins, ns = route.incident_s_bins, npsi = route.incident_psi_bins;
  BssrdfGrid grid;  // summed over the whole axis, surface reflection included
  grid.u_bins = nu;
  grid.direction_resolution = R;
  const BssrdfResult bssrdf =
      simulate_bssrdf(fiber, grid, BssrdfIncidence::binned(ns, npsi), batch_of(s, progress));

  // T = F_out / F_in per incident bin: the BSSRDF of the paper times the exit cell's geometry
  // (Delta omega_out B_i cos theta_out), summed over the axial offset.
  const size_t incident_bins = static_cast<size_t>(ns) * npsi;
  std::vector<double> t_total(bssrdf.exit_weight);
  for (size_t a = 0; a < incident_bins; ++a) {
    const double inv = bssrdf.flux_in[a] > 0 ? 1 / bssrdf.flux_in[a] : 0;
    for (size_t k = 0; k < grid.cells(); ++k) t_total[a * grid.cells() + k] *= inv;
  }

  // BRDF of cell B: the paper's sum over lit cells A_j at offsets -pi + j du (j = 0 .. nu - 1; the
  // BSSRDF's u cell of that offset is (j + nu / 2) mod nu), integrated over the incident table bin
  // by a cq x cq midpoint rule. B sits at the top; A_j at angle pi/2 - offset_j.
  const double du = 2 * kPi / nu;
  std::vector<Frame> frames_aj;
  for (int j = 0; j < nu; ++j)
    frames_aj.push_back(CylinderGeometry::cylinder_frame(kPi / 2 - (-kPi + j * du)));
  const int cq = route.cell_quadrature;
  const double point_solid_angle = table_grid.bin_solid_angle() / (cq * cq);
  std::vector<double> weighted(cells * cells, 0.0);
  parallel_for(cells, s.threads, [&](uint64_t i) {
    double* row = &weighted[i * cells];
    for (int qa = 0; qa < cq; ++qa)
      for (int qb = 0; qb < cq; ++qb) {
        const Vec3 omega = DirectionGrid::to_direction(table_grid.chart_point(
            static_cast<int>(i), (qb + 0.5) / cq, (qa + 0.5) / cq));  // world = B's frame
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
          const int iu = (j + nu / 2) % nu;
          for (int c = 0; c < 4; ++c) {
            if (cw[c] == 0) continue;
            const double* t = &t_total[corner[c] * grid.cells() + grid.index(iu, 0, 0)];
            const double wc = w * cw[c];
            for (size_t o = 0; o < cells; ++o) row[o] += wc * t[o];
          }
        }
      }
  });
  return finish_table(R, std::move(weighted), bssrdf.books, bssrdf.cancelled);
}

}  // namespace weft
