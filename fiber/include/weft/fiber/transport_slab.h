#pragma once
// Slab simulations for validation: a pencil beam of unit power hits the top face of a
// plane-parallel slab (geometry and conventions in transport.h) and every quantity MCML reports
// is estimated with its standard error. All values are fractions of the incident power.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

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

// `weft slab` as a request: the slab's optical properties (per mm), its indices and thickness
// ("inf": semi-infinite), the beam's incidence, and the photons traced.
struct SlabRequest {
  double mua_per_mm = 0, mus_per_mm = 0, g = 0, n_slab = 1, n_above = 1, n_below = 1;
  std::string thickness_mm;
  double incidence_deg = 0;
  int64_t photons = 0;
  uint64_t seed = 0;
  int threads = TaskBatch{}.threads;
  int64_t photons_per_task = static_cast<int64_t>(TaskBatch{}.items_per_task);
  bool analog = false;  // analog absorption instead of implicit capture
};
struct SlabPlan {
  SlabRequest request;
  SlabSetup setup;
  TaskBatch batch;  // without progress
};
// weft::Error naming the option ("--g", "--thickness-mm") at fault.
SlabPlan plan_slab(const SlabRequest& request);
struct SlabOutcome {
  SlabResult result;
  nlohmann::json summary;  // what `weft slab --json` prints
};
SlabOutcome run_slab(const SlabPlan& plan, const ProgressCallback& progress);
// The quantities of a result, as `weft slab` names them, in its order.
std::vector<std::pair<const char*, MeanEstimate>> slab_quantities(const SlabResult& r);

}  // namespace weft
