#include "weft/materials/fabric/transport_bssrdf.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace weft {
namespace {

// One tally type serves as task tally (a list of exits, no table) and as the total (the table):
// adding a task tally to the total replays its exits in order.
struct BssrdfTally {
  struct Exit {
    uint32_t cell;
    double weight;
  };
  std::vector<Exit> exits;
  double overflow = 0;
  std::optional<BssrdfRecorder> table;  // the total only
  MeanAccumulator specular, exited, absorbed, roulette, lost;
  uint64_t photons = 0, scatterings = 0;

  BssrdfTally& operator+=(const BssrdfTally& o) {
    for (const Exit& e : o.exits) table->add(e.cell, e.weight);
    table->add_overflow(o.overflow);
    specular += o.specular;
    exited += o.exited;
    absorbed += o.absorbed;
    roulette += o.roulette;
    lost += o.lost;
    photons += o.photons;
    scatterings += o.scatterings;
    return *this;
  }
};

// Records into a task's exit list.
struct ExitListRecorder {
  const BssrdfBinner* binner;
  BssrdfTally* tally;
  void on_exit(const ExitEvent& e) {
    const int64_t k = binner->cell(e);
    if (k < 0)
      tally->overflow += e.weight;
    else
      tally->exits.push_back({static_cast<uint32_t>(k), e.weight});
  }
};

}  // namespace

void BssrdfGridSpec::validate() const {
  if (u_bins < 1 || u_bins > 4096) throw Error("", "u_bins", "must lie in [1, 4096]");
  if (v_bins < 1 || v_bins > 4096) throw Error("", "v_bins", "must lie in [1, 4096]");
  if (theta_bins < 1 || theta_bins > 1024) throw Error("", "theta_bins", "must lie in [1, 1024]");
  if (phi_bins < 1 || phi_bins > 1024) throw Error("", "phi_bins", "must lie in [1, 1024]");
  if (!std::isfinite(v_range) || !(v_range > 0))
    throw Error("", "v_range", "must be finite and > 0");
  if (cells() > (size_t{1} << 28)) throw Error("", "grid", "more than 2^28 cells");
}

BssrdfBinner::BssrdfBinner(const BssrdfGridSpec& grid, double radius)
    : grid_(grid), radius_(radius) {
  grid_.validate();
  if (!std::isfinite(radius) || !(radius > 0)) throw Error("", "radius", "must be finite and > 0");
  u_scale_ = grid_.u_bins / (2 * kPi);
  v_scale_ = grid_.v_bins / (2 * grid_.v_range);
  phi_scale_ = grid_.phi_bins / (2 * kPi);
}

int64_t BssrdfBinner::cell(const ExitEvent& e) const {
  const Vec3& p = e.position;
  const double fv = std::floor((p.x + grid_.v_range) * v_scale_);
  if (!(fv >= 0 && fv < grid_.v_bins)) return -1;
  const int iv = static_cast<int>(fv);
  // A sits at angle 0 (the point (0, r, 0)); cell k is centred on 2 pi k / u_bins.
  const double u = std::atan2(p.z, p.y);  // [-pi, pi]
  int iu = static_cast<int>(std::floor(u * u_scale_ + 0.5));
  iu = ((iu % grid_.u_bins) + grid_.u_bins) % grid_.u_bins;
  // Local frame at the exit point: t = x, b = n x t = (0, n.z, -n.y), n = (0, y, z) / r.
  const double ny = p.y / radius_, nz = p.z / radius_;
  const Vec3& d = e.direction;
  const double lx = d.x, ly = d.y * nz - d.z * ny, lz = d.y * ny + d.z * nz;
  const int it = std::clamp(static_cast<int>(lz * grid_.theta_bins), 0, grid_.theta_bins - 1);
  double phi = std::atan2(ly, lx);
  if (phi < 0) phi += 2 * kPi;
  const int ip = std::min(static_cast<int>(phi * phi_scale_), grid_.phi_bins - 1);
  return static_cast<int64_t>(grid_.index(iu, iv, it, ip));
}

BssrdfRecorder::BssrdfRecorder(const BssrdfGridSpec& grid, double radius) : binner_(grid, radius) {
  sum_.assign(grid.cells(), 0.0);
  sum2_.assign(grid.cells(), 0.0);
}

double BssrdfRecorder::binned() const {
  double s = 0;
  for (double v : sum_) s += v;
  return s;
}

void BssrdfSetup::validate() const {
  medium.validate();
  options.validate();
  grid.validate();
  (void)CylinderGeometry(radius, n_outside);
  if (!is_finite(incident) || std::abs(length_squared(incident) - 1) > 1e-9 || !(incident.z > 0))
    throw Error("", "incident", "must be a unit vector with z > 0 (towards the light)");
}

double BssrdfTable::cell_area() const {
  return radius * (2 * kPi / grid.u_bins) * (2 * grid.v_range / grid.v_bins);
}

double BssrdfTable::projected_solid_angle(int theta_bin) const {
  const double c0 = static_cast<double>(theta_bin) / grid.theta_bins;
  const double c1 = static_cast<double>(theta_bin + 1) / grid.theta_bins;
  return (2 * kPi / grid.phi_bins) * 0.5 * (c1 * c1 - c0 * c0);
}

double BssrdfTable::u_center(int iu) const {
  const double u = 2 * kPi * iu / grid.u_bins;
  return u > kPi ? u - 2 * kPi : u;
}

double BssrdfTable::v_center(int iv) const {
  return -grid.v_range + (iv + 0.5) * (2 * grid.v_range / grid.v_bins);
}

Vec3 BssrdfTable::direction_center(int it, int ip) const {
  const double c = (it + 0.5) / grid.theta_bins;
  const double phi = 2 * kPi * (ip + 0.5) / grid.phi_bins;
  const double s = safe_sqrt(1 - c * c);
  return {s * std::cos(phi), s * std::sin(phi), c};
}

BssrdfTable simulate_bssrdf(const BssrdfSetup& setup, const PhotonBatchOptions& batch) {
  setup.validate();
  const CylinderTransport transport(CylinderGeometry(setup.radius, setup.n_outside), setup.medium,
                                    setup.options);
  const Frame frame_a = CylinderGeometry::cylinder_frame(0);
  const Vec3 entry = transport.geometry().surface_point(0, 0);
  const Vec3 travel = -normalize(frame_a.to_world(setup.incident));

  const BssrdfBinner binner(setup.grid, setup.radius);
  BssrdfTally total;
  total.table.emplace(setup.grid, setup.radius);
  const PhotonBatchStatus status =
      run_photon_tasks(batch, BssrdfTally{}, total,
                       [&](uint64_t, uint64_t, uint64_t count, Rng& rng, BssrdfTally& tally) {
                         tally.exits.reserve(count);
                         ExitListRecorder recorder{&binner, &tally};
                         for (uint64_t i = 0; i < count; ++i) {
                           PhotonTally photon;
                           transport.launch_external(CylinderGeometry::kSurface, entry, travel, 1.0,
                                                     rng, recorder, photon);
                           tally.specular.add(photon.specular);
                           tally.exited.add(photon.exited);
                           tally.absorbed.add(photon.absorbed);
                           tally.roulette.add(photon.roulette_loss - photon.roulette_gain);
                           tally.lost.add(photon.lost);
                           tally.photons += 1;
                           tally.scatterings += photon.scatterings;
                         }
                       });

  BssrdfTable t;
  t.grid = setup.grid;
  t.radius = setup.radius;
  t.incident = setup.incident;
  const uint64_t n = total.photons;
  t.photons = n;
  t.scatterings = total.scatterings;
  t.cancelled = status.cancelled;
  t.specular = total.specular.estimate(n);
  t.exited = total.exited.estimate(n);
  t.absorbed = total.absorbed.estimate(n);
  t.roulette = total.roulette.estimate(n);
  t.lost = total.lost.estimate(n);
  t.overflow = n > 0 ? total.table->overflow() / static_cast<double>(n) : 0.0;
  t.value.assign(setup.grid.cells(), 0.0);
  t.std_error.assign(setup.grid.cells(), 0.0);
  if (n == 0) return t;
  const double area = t.cell_area();
  // Cells are independent: convert them in parallel (same bits at any thread count).
  parallel_for(static_cast<uint64_t>(t.grid.u_bins), batch.threads, [&](uint64_t task) {
    const int iu = static_cast<int>(task);
    for (int iv = 0; iv < t.grid.v_bins; ++iv)
      for (int it = 0; it < t.grid.theta_bins; ++it) {
        const double scale = 1 / (area * t.projected_solid_angle(it));
        for (int ip = 0; ip < t.grid.phi_bins; ++ip) {
          const size_t k = t.grid.index(iu, iv, it, ip);
          const MeanEstimate e =
              MeanAccumulator{total.table->weight_sum()[k], total.table->weight_sum2()[k]}.estimate(
                  n);
          t.value[k] = e.mean * scale;
          t.std_error[k] = e.std_error * scale;
        }
      }
  });
  return t;
}

}  // namespace weft
