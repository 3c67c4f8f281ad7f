#include "weft/fiber/transport_slab.h"

#include <array>
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

// The energy books and, beyond them, the exits split by face and by scattering: rb, rd, tb, td,
// tt in that order.
struct SlabTally {
  PhotonStats books;
  std::array<MeanAccumulator, 5> faces;

  SlabTally& operator+=(const SlabTally& o) {
    books += o.books;
    for (size_t k = 0; k < faces.size(); ++k) faces[k] += o.faces[k];
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

SlabResult simulate_slab(const SlabSetup& setup, const TaskBatch& batch) {
  setup.validate();
  const SlabTransport transport(SlabGeometry(setup.thickness, setup.n_above, setup.n_below),
                                setup.medium, setup.options);
  const Vec3 direction{std::sin(setup.incidence_rad), 0, -std::cos(setup.incidence_rad)};

  SlabTally total;
  const TaskBatchStatus status = run_batch<SlabTally>(
      photon_batch(batch),
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, SlabTally& tally) {
        for (uint64_t i = 0; i < count; ++i) {
          PhotonTally photon;
          SlabExitRecorder exits;
          transport.launch_external(SlabGeometry::kTop, Vec3{0, 0, 0}, direction, 1.0, rng, exits,
                                    photon);
          tally.books.add(photon);
          const double faces[5] = {exits.top_unscattered, exits.top_scattered,
                                   exits.bottom_unscattered, exits.bottom_scattered,
                                   exits.bottom_unscattered + exits.bottom_scattered};
          for (size_t k = 0; k < 5; ++k) tally.faces[k].add(faces[k]);
        }
      },
      [&](const SlabTally& t) { total += t; });

  SlabResult r;
  static_cast<PhotonFractions&>(r) = total.books.fractions();
  const uint64_t n = total.books.photons;
  MeanEstimate* faces[5] = {&r.rb, &r.rd, &r.tb, &r.td, &r.tt};
  for (size_t k = 0; k < 5; ++k) *faces[k] = total.faces[k].estimate(n);
  r.cancelled = status.cancelled;
  return r;
}

}  // namespace weft
