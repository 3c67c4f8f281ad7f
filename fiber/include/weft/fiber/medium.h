#pragma once
// The scattering medium inside a fiber, per spectral band: what photon transport needs.
//
// For each band (centre wavelength lambda) and each particle species s with volume fraction f_s:
//   N_s = f_s / <V_s>                  number density (1/um^3), <V> = <4/3 pi r^3> of the
//                                       size distribution (monodisperse: 4/3 pi r^3)
//   mu_s = sum_s N_s <C_sca,s>          scattering coefficient (1/um)
//   mu_a = sum_s N_s <C_abs,s> + (1 - sum_s f_s) alpha_host
// Cross sections come from Mie theory with m = (n_s + i k_s) / n_host and x = 2 pi n_host r /
// lambda (the wavelength inside the host is lambda / n_host); the host's own absorption
// (the dye) is added as alpha_host over the volume the host occupies. The phase function is the
// sigma_sca-weighted average of the species' (number-averaged) phase functions, tabulated in
// mu = cos theta on a grid that resolves the forward peak of the largest particles.
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/phase_function.h"

namespace weft {

struct MediumBand {
  int band = 0;
  double wavelength_nm = 0;
  double host_n = 0;
  double mu_s_per_um = 0;
  double mu_a_per_um = 0;  // particles + host
  double mu_a_host_per_um = 0;
  double mu_a_particles_per_um = 0;
  double albedo = 0;  // mu_s / (mu_s + mu_a); 0 when the medium is empty
  double g = 0;       // Mie asymmetry parameter of the combined phase function
  PhaseFunction phase = PhaseFunction::henyey_greenstein(0.0);  // tabulated; isotropic if empty

  double mu_t_per_um() const { return mu_s_per_um + mu_a_per_um; }
};

struct MediumOptions {
  int lognormal_nodes = 64;     // radius quadrature nodes per lognormal species
  int max_angle_nodes = 20000;  // cap on the phase-function grid
  int threads = 0;              // 0 = all cores; results do not depend on it
};

struct FiberMedium {
  std::string spec_name;
  std::string spec_hash;  // fiber_spec_hash_hex of the spec
  double fiber_radius_um = 0;
  std::vector<MediumBand> bands;  // in the order requested
};

// One band (0 .. kNumBands-1) of the medium.
MediumBand compute_medium_band(const FiberSpec& spec, int band, const MediumOptions& options = {});

// The bands requested (all 33 when 'bands' is empty), computed in parallel over bands. Progress
// reports bands done; a callback returning false cancels (weft::Error "cancelled").
FiberMedium build_fiber_medium(const FiberSpec& spec, std::span<const int> bands = {},
                               const MediumOptions& options = {},
                               const ProgressCallback& progress = {});

// `weft medium` as a request: a spec file or preset, the band centres asked (empty: all 33 bands)
// and the threads.
struct MediumRequest {
  std::string spec;
  std::vector<double> wavelengths_nm;
  int threads = MediumOptions{}.threads;
};
struct MediumPlan {
  FiberSpec spec;
  std::vector<int> bands;
  MediumOptions options;
};
// weft::Error naming the option at fault ("--wavelengths-nm": not a band centre; "--threads").
MediumPlan plan_medium(const MediumRequest& request);
// The medium's bands, as the JSON `weft medium --json` prints.
nlohmann::json run_medium(const MediumPlan& plan, const ProgressCallback& progress);

}  // namespace weft
