#include "weft/fiber/bssrdf.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"

namespace weft {
namespace {

// A task's exits in the order they happened: (index into exit_weight, weight). Sparse, because a
// task's photons touch few cells; merged in task order, so sums are the same at any thread count.
struct BssrdfTaskTally {
  std::vector<std::pair<uint64_t, double>> exits;
  std::vector<double> flux_in;
  std::vector<uint64_t> photons_in;
  double overflow = 0;
  PhotonTally books;
};

// Angle of A around the axis: the top of the fiber, whose local frame is the world frame.
constexpr double kEntryAngle = kPi / 2;

}  // namespace

void BssrdfGrid::validate() const {
  if (u_bins < 2 || u_bins > 4096 || u_bins % 2 != 0)
    throw Error("", "u_bins", "must be even and lie in [2, 4096]");
  if (v_bins < 1 || v_bins > 4096) throw Error("", "v_bins", "must lie in [1, 4096]");
  if (std::isnan(v_range) || !(v_range > 0)) throw Error("", "v_range", "must be > 0");
  if (!std::isfinite(v_range) && v_bins != 1)
    throw Error("", "v_bins", "an infinite axial window has one cell (v_bins = 1)");
  if (direction_resolution < 1 || direction_resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "direction_resolution",
                "must lie in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
}

double BssrdfGrid::u_center(int iu) const {
  const double u = 2 * kPi * iu / u_bins;
  return u > kPi ? u - 2 * kPi : u;
}

double BssrdfGrid::v_center(int iv) const {
  return std::isfinite(v_range) ? -v_range + (iv + 0.5) * (2 * v_range / v_bins) : 0.0;
}

int64_t BssrdfGrid::cell_of(const ExitEvent& e) const {
  const int nu = u_bins;
  const double du = 2 * kPi / nu;
  const double phi_b = std::atan2(e.position.z, e.position.y);
  double offset = phi_b - kEntryAngle;  // angle of B from A, wrapped to [-pi, pi)
  offset -= 2 * kPi * std::floor((offset + kPi) / (2 * kPi));
  // Cells centred on multiples of du: offset 0 (the surface reflection) is a centre.
  const int j = static_cast<int>(std::floor((offset + kPi) / du + 0.5)) % nu;
  const int iu = (j + nu / 2) % nu;
  int iv = 0;
  if (std::isfinite(v_range)) {
    const double fv = std::floor((e.position.x + v_range) * (v_bins / (2 * v_range)));
    if (!(fv >= 0 && fv < v_bins)) return -1;
    iv = static_cast<int>(fv);
  }
  const int o = directions().bin_of(CylinderGeometry::cylinder_frame(phi_b).to_local(e.direction));
  return static_cast<int64_t>(index(iu, iv, o));
}

BssrdfIncidence BssrdfIncidence::from(const Vec3& w_in) {
  BssrdfIncidence i;
  i.direction = w_in;
  return i;
}

BssrdfIncidence BssrdfIncidence::binned(int s_bins, int psi_bins) {
  BssrdfIncidence i;
  i.s_bins = s_bins;
  i.psi_bins = psi_bins;
  return i;
}

void BssrdfIncidence::validate() const {
  if (direction) {
    const Vec3& w = *direction;
    if (!is_finite(w) || std::abs(length_squared(w) - 1) > 1e-9 || !(w.z > 0))
      throw Error("", "incident", "must be a unit vector with z > 0 (towards the light)");
  } else if (s_bins < 1 || psi_bins < 1 || static_cast<int64_t>(s_bins) * psi_bins > (1 << 20)) {
    throw Error("", "incident_bins", "need 1 to 2^20 incident bins (s_bins x psi_bins)");
  }
}

double BssrdfResult::transfer(int bin, size_t cell) const {
  const double f = flux_in[bin];
  return f > 0 ? exit_weight[bin * grid.cells() + cell] / f : 0.0;
}

double BssrdfResult::cell_area() const {
  return radius * (2 * kPi / grid.u_bins) * (2 * grid.v_range / grid.v_bins);
}

MeanEstimate BssrdfResult::value(int bin, int iu, int iv, int direction_bin) const {
  const size_t k = bin * grid.cells() + grid.index(iu, iv, direction_bin);
  const uint64_t n = photons_in[bin];
  if (n == 0 || !(flux_in[bin] > 0)) return {};
  // Exit weight per photon of the bin, over the mean power a photon brought.
  const MeanEstimate per_photon =
      MeanAccumulator{exit_weight[k], exit_weight2.empty() ? 0.0 : exit_weight2[k]}.estimate(n);
  const double scale = static_cast<double>(n) / flux_in[bin] /
                       (cell_area() * direction_areas_[static_cast<size_t>(direction_bin)]);
  return {per_photon.mean * scale, exit_weight2.empty() ? 0.0 : per_photon.std_error * scale};
}

BssrdfResult simulate_bssrdf(const FiberBandPhysics& fiber, const BssrdfGrid& grid,
                             const BssrdfIncidence& incidence, const TaskBatch& batch) {
  fiber.validate();
  grid.validate();
  incidence.validate();
  const int bins = incidence.bins();
  const size_t table_size = static_cast<size_t>(bins) * grid.cells();
  if (table_size > (size_t{1} << 27))  // 1 GiB of doubles
    throw Error("", "bssrdf_grid",
                "the BSSRDF table (incident bins x exit cells = " + std::to_string(table_size) +
                    " values) is too large; use a coarser grid");
  const int ns = incidence.s_bins, npsi = incidence.psi_bins;
  const double radius = fiber.interior.geometry.radius();
  const Frame frame_a = CylinderGeometry::cylinder_frame(kEntryAngle);

  BssrdfResult r;
  r.grid = grid;
  r.incidence = incidence;
  r.radius = radius;
  r.direction_areas_ = grid.directions().cosine_weighted_areas();
  r.exit_weight.assign(table_size, 0.0);
  if (grid.keep_squares) r.exit_weight2.assign(table_size, 0.0);
  r.flux_in.assign(static_cast<size_t>(bins), 0.0);
  r.photons_in.assign(static_cast<size_t>(bins), 0);

  const TaskBatchStatus status = run_batch<BssrdfTaskTally>(
      photon_batch(batch),
      [&](uint64_t, uint64_t first, uint64_t count, Rng& rng, BssrdfTaskTally& tally) {
        tally.exits.reserve(2 * count);
        tally.flux_in.assign(static_cast<size_t>(bins), 0.0);
        tally.photons_in.assign(static_cast<size_t>(bins), 0);
        size_t a = 0;  // the incident bin of the photon in flight
        const ExitSink bin_exit = [&](const ExitEvent& e) {
          const int64_t cell = grid.cell_of(e);
          if (cell < 0)
            tally.overflow += e.weight;
          else
            tally.exits.emplace_back(a * grid.cells() + static_cast<uint64_t>(cell), e.weight);
        };
        // Without surface_in_table the surface reflection is booked (books.specular) only.
        const ExitSink no_exit;
        const ExitSink& surface_exit = grid.surface_in_table ? bin_exit : no_exit;
        for (uint64_t k = 0; k < count; ++k) {
          Vec3 omega_local;
          double w0 = 1;
          if (incidence.direction) {
            omega_local = *incidence.direction;
          } else {
            // Incident bins in turn (stratified); direction uniform in (s, psi) inside the bin,
            // which is uniform in solid angle; the flux it carries is proportional to cos theta_A.
            a = (first + k) % static_cast<size_t>(bins);
            const int is = static_cast<int>(a / npsi), ip = static_cast<int>(a % npsi);
            const double s_axial = -1 + 2 * (is + rng.uniform()) / ns;
            const double psi = -kPi / 2 + kPi * (ip + rng.uniform()) / npsi;
            const double c = safe_sqrt(1 - s_axial * s_axial);
            omega_local = {s_axial, c * std::sin(psi), c * std::cos(psi)};
            w0 = omega_local.z;
          }
          tally.flux_in[a] += w0;
          tally.photons_in[a] += 1;
          enter_fiber(fiber, kEntryAngle, frame_a.to_world(omega_local), w0, rng, surface_exit,
                      bin_exit, tally.books);
        }
      },
      [&](const BssrdfTaskTally& t) {
        for (const auto& [k, w] : t.exits) {
          r.exit_weight[k] += w;
          if (grid.keep_squares) r.exit_weight2[k] += w * w;
        }
        for (size_t b = 0; b < r.flux_in.size(); ++b) {
          r.flux_in[b] += t.flux_in[b];
          r.photons_in[b] += t.photons_in[b];
        }
        r.overflow += t.overflow;
        r.books += t.books;
      });
  r.cancelled = status.cancelled;
  return r;
}

}  // namespace weft
