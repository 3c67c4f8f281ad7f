#include "weft/fiber/transport_cylinder.h"

#include <cmath>

namespace weft {

Vec3 cylinder_beam_entry(const CylinderGeometry& geometry, const Vec3& direction, double u) {
  const double s = std::hypot(direction.y, direction.z);
  if (!(s > 0)) throw Error("", "direction", "a beam along the cylinder axis never enters it");
  const double uy = direction.y / s, uz = direction.z / s;  // beam direction in the cross-section
  const double r = geometry.radius();
  const double b = r * (2 * u - 1);
  const double depth = safe_sqrt(r * r - b * b);
  // Offset b along the in-plane perpendicular (-uz, uy), then back up the beam to the wall.
  return geometry.snap(Vec3{0, -b * uz - depth * uy, b * uy - depth * uz},
                       CylinderGeometry::kSurface);
}

void CylinderBeamSetup::validate() const {
  medium.validate();
  options.validate();
  (void)CylinderGeometry(radius, n_outside);
  if (!is_finite(direction) || std::abs(length_squared(direction) - 1) > 1e-9)
    throw Error("", "direction", "must be a finite unit vector");
  if (!(std::hypot(direction.y, direction.z) > 1e-12))
    throw Error("", "direction", "a beam along the cylinder axis never enters it");
}

CylinderBeamResult simulate_cylinder_beam(const CylinderBeamSetup& setup, const TaskBatch& batch) {
  setup.validate();
  const CylinderTransport transport(CylinderGeometry(setup.radius, setup.n_outside), setup.medium,
                                    setup.options);
  PhotonStats total;
  const TaskBatchStatus status = run_batch<PhotonStats>(
      photon_batch(batch),
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, PhotonStats& tally) {
        NullRecorder none;
        for (uint64_t i = 0; i < count; ++i) {
          PhotonTally photon;
          const Vec3 p = cylinder_beam_entry(transport.geometry(), setup.direction, rng.uniform());
          transport.launch_external(CylinderGeometry::kSurface, p, setup.direction, 1.0, rng, none,
                                    photon);
          tally.add(photon);
        }
      },
      [&](const PhotonStats& t) { total += t; });
  CylinderBeamResult r;
  static_cast<PhotonFractions&>(r) = total.fractions();
  r.cancelled = status.cancelled;
  return r;
}

}  // namespace weft
