#pragma once
// `weft mie` as a request (the sphere or ensemble asked for), its plan (the checks) and its run
// (the efficiencies, g, and at the angles asked the amplitudes and phase function, as the JSON the
// command prints). Ranges are mie.h's to check: its errors name the field.
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

namespace weft {

struct MieRequest {
  // Relative: m = m_re + i m_im (m_im not given: 0) and the size parameter x.
  std::optional<double> m_re, m_im, x;
  // Physical: a particle n + ik (k not given: 0) of this radius in a host of index host_n at a
  // vacuum wavelength; with lognormal_sigma, a lognormal ensemble of median radius radius_um.
  std::optional<double> particle_n, particle_k, host_n, radius_um, wavelength_nm, lognormal_sigma;
  std::vector<double> angles_deg;  // scattering angles for S1, S2 and p(theta)
};

struct MiePlan {
  MieRequest request;
  bool relative = true;    // m and x, else the physical quantities
  std::vector<double> mu;  // the angles' cosines
};

// weft::Error naming the option ("--particle-n", "--angles-deg") at fault: relative and physical
// quantities mixed, neither given, a required one missing, an angle outside [0, 180] degrees.
MiePlan plan_mie(const MieRequest& request);
// The summary `weft mie --json` prints.
nlohmann::json run_mie(const MiePlan& plan);

}  // namespace weft
