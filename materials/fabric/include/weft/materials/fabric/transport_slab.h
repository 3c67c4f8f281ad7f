#pragma once
// Slab simulations for validation: a pencil beam of unit power hits the top face of a
// plane-parallel slab (geometry and conventions in transport.h) and every quantity MCML reports
// is estimated with its standard error. All values are fractions of the incident power.
#include <cstdint>

#include "weft/materials/fabric/transport.h"
#include "weft/materials/fabric/transport_batch.h"

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

struct SlabResult {
  MeanEstimate rsp;  // specular: Fresnel reflection at entry
  MeanEstimate rb;   // unscattered light leaving the top face after entering (internal bounces)
  MeanEstimate rd;   // diffuse reflectance: scattered light leaving the top face
  MeanEstimate tb;   // ballistic transmittance: unscattered light leaving the bottom face
  MeanEstimate td;   // diffuse transmittance: scattered light leaving the bottom face
  MeanEstimate tt;   // total transmittance td + tb
  MeanEstimate absorbed;  // weight deposited in the medium
  MeanEstimate roulette;  // roulette losses minus gains (mean zero; nonzero by chance only)
  MeanEstimate lost;      // interaction cap reached (see TransportOptions::max_events)
  // 1 - (rsp + rb + rd + tb + td + absorbed + roulette + lost): zero up to rounding.
  double energy_imbalance = 0;
  uint64_t photons = 0;      // photons actually traced (fewer than asked when cancelled)
  uint64_t scatterings = 0;  // scattering events in all
  uint64_t reflections = 0;  // internal reflections in all
  bool cancelled = false;
};

SlabResult simulate_slab(const SlabSetup& setup, const PhotonBatchOptions& batch);

}  // namespace weft
