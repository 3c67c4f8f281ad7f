#pragma once
// A parallel beam over a whole cylinder (the fiber): photons arrive along one direction, spread
// uniformly over the projected width 2 r, and the fate of the incident power is estimated.
// Geometry and conventions are those of transport.h (axis along x).
#include <cstdint>

#include "weft/fiber/transport.h"
#include "weft/fiber/transport_batch.h"

namespace weft {

// Entry point on the wall for a beam travelling along unit 'direction' (not parallel to the
// axis), with impact parameter b = r (2 u - 1) across the projected width; axial coordinate 0
// (the cylinder is invariant along its axis).
Vec3 cylinder_beam_entry(const CylinderGeometry& geometry, const Vec3& direction, double u);

struct CylinderBeamSetup {
  TransportMedium medium;
  double radius = 1;
  double n_outside = 1;
  Vec3 direction{0, 0, -1};  // travel direction of the beam, unit, not along the axis (x)
  TransportOptions options;

  void validate() const;  // weft::Error naming the field
};

// Fractions of the power hitting the cylinder (specular: Fresnel reflection at entry; exited:
// left the cylinder after entering, anywhere on the wall).
struct CylinderBeamResult : PhotonFractions {
  bool cancelled = false;
};

CylinderBeamResult simulate_cylinder_beam(const CylinderBeamSetup& setup, const TaskBatch& batch);

}  // namespace weft
