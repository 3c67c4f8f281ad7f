#pragma once
// Slab simulations for validation: a pencil beam of unit power hits the top face of a
// plane-parallel slab (geometry and conventions in transport.h) and every quantity MCML reports
// is estimated with its standard error. All values are fractions of the incident power.
#include <cstdint>

#include "weft/fiber/transport.h"
#include "weft/fiber/transport_batch.h"

namespace weft {

struct SlabSetup {
  TransportMedium medium;
  double thickness = kTransportInfinity;  // > 0; +infinity: semi-infinite
  double n_above = 1, n_below = 1;
  double incidence_rad = 0;  // angle of the incident beam from the normal, in [0, pi/2)
  TransportOptions options;

  // Throws weft::Error naming the field.
  void validate() const;
};

// The books (specular is MCML's rsp; exited = rb + rd + tb + td) and the exits split by face and
// by whether the photon scattered.
struct SlabResult : PhotonFractions {
  MeanEstimate rb;  // unscattered light leaving the top face after entering (internal bounces)
  MeanEstimate rd;  // diffuse reflectance: scattered light leaving the top face
  MeanEstimate tb;  // ballistic transmittance: unscattered light leaving the bottom face
  MeanEstimate td;  // diffuse transmittance: scattered light leaving the bottom face
  MeanEstimate tt;  // total transmittance td + tb
  bool cancelled = false;
};

SlabResult simulate_slab(const SlabSetup& setup, const TaskBatch& batch);

}  // namespace weft
