#include "weft/materials/fabric/transport_slab.h"

#include <cmath>

namespace weft {
namespace {

// Per-photon exit sums, split by face and by whether the photon scattered.
struct SlabExitRecorder {
  double top_unscattered = 0, top_scattered = 0, bottom_unscattered = 0, bottom_scattered = 0;

  void on_exit(const ExitEvent& e) {
    const bool scattered = e.scatterings > 0;
    if (e.boundary == SlabGeometry::kTop)
      (scattered ? top_scattered : top_unscattered) += e.weight;
    else
      (scattered ? bottom_scattered : bottom_unscattered) += e.weight;
  }
};

// The energy books and, beyond them, the exits split by face and by scattering.
struct SlabTally {
  PhotonStats books;
  MeanAccumulator rb, rd, tb, td, tt;

  SlabTally& operator+=(const SlabTally& o) {
    books += o.books;
    rb += o.rb;
    rd += o.rd;
    tb += o.tb;
    td += o.td;
    tt += o.tt;
    return *this;
  }
};

}  // namespace

void SlabSetup::validate() const {
  medium.validate();
  options.validate();
  (void)SlabGeometry(thickness, n_above, n_below);
  if (!std::isfinite(incidence_rad) || incidence_rad < 0 || !(incidence_rad < kPi / 2))
    throw Error("", "incidence", "must lie in [0, 90) degrees");
  if (!std::isfinite(thickness) && !(medium.mu_a + medium.mu_s > 0))
    throw Error("", "thickness",
                "a semi-infinite slab needs mu_a + mu_s > 0 (light would travel without end)");
}

SlabResult simulate_slab(const SlabSetup& setup, const PhotonBatchOptions& batch) {
  setup.validate();
  const SlabTransport transport(SlabGeometry(setup.thickness, setup.n_above, setup.n_below),
                                setup.medium, setup.options);
  const Vec3 direction{std::sin(setup.incidence_rad), 0, -std::cos(setup.incidence_rad)};

  SlabTally total;
  const PhotonBatchStatus status = run_photon_tasks<SlabTally>(
      batch,
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, SlabTally& tally) {
        for (uint64_t i = 0; i < count; ++i) {
          PhotonTally photon;
          SlabExitRecorder exits;
          transport.launch_external(SlabGeometry::kTop, Vec3{0, 0, 0}, direction, 1.0, rng, exits,
                                    photon);
          tally.books.add(photon);
          tally.rb.add(exits.top_unscattered);
          tally.rd.add(exits.top_scattered);
          tally.tb.add(exits.bottom_unscattered);
          tally.td.add(exits.bottom_scattered);
          tally.tt.add(exits.bottom_unscattered + exits.bottom_scattered);
        }
      },
      [&](const SlabTally& t) { total += t; });

  SlabResult r;
  const PhotonStats& books = total.books;
  const uint64_t n = books.photons;
  r.rsp = books.specular.estimate(n);
  r.rb = total.rb.estimate(n);
  r.rd = total.rd.estimate(n);
  r.tb = total.tb.estimate(n);
  r.td = total.td.estimate(n);
  r.tt = total.tt.estimate(n);
  r.absorbed = books.absorbed.estimate(n);
  r.roulette = books.roulette.estimate(n);
  r.lost = books.lost.estimate(n);
  r.energy_imbalance = n == 0 ? 0.0
                              : 1.0 - (r.rsp.mean + r.rb.mean + r.rd.mean + r.tb.mean + r.td.mean +
                                       r.absorbed.mean + r.roulette.mean + r.lost.mean);
  r.photons = n;
  r.scatterings = books.scatterings;
  r.reflections = books.reflections;
  r.cancelled = status.cancelled;
  return r;
}

}  // namespace weft
