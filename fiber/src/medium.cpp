#include "weft/fiber/medium.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"

namespace weft {

MediumBand compute_medium_band(const FiberSpec& spec, int band, const MediumOptions& options) {
  if (band < 0 || band >= kNumBands)
    throw Error("", "band",
                "band " + std::to_string(band) + " outside 0.." + std::to_string(kNumBands - 1));
  MediumBand out;
  out.band = band;
  out.wavelength_nm = band_wavelength_nm(band);
  out.host_n = spec.host_n[band];
  const double wavenumber = 2 * kPi * out.host_n / (out.wavelength_nm * 1e-3);  // 1/um

  // One angle grid for every species: it must resolve the forward peak of the largest sphere
  // any of them puts into its radius quadrature.
  double x_max = 0, total_fraction = 0;
  for (const auto& s : spec.species) {
    total_fraction += s.volume_fraction;
    if (s.volume_fraction <= 0) continue;
    const SizeQuadrature q = size_quadrature(s.size, options.lognormal_nodes);
    for (double r : q.radius_um) x_max = std::max(x_max, wavenumber * r);
  }
  out.mu_a_host_per_um = (1 - total_fraction) * host_total_absorption_per_um(spec)[band];

  std::vector<double> mu;  // increasing, -1 .. 1, without duplicates from cos near 0 and pi
  if (x_max > 0) {
    const std::vector<double> theta = mie_angle_grid_rad(x_max, options.max_angle_nodes);
    for (auto it = theta.rbegin(); it != theta.rend(); ++it) {
      const double m = std::cos(*it);
      if (mu.empty() || m > mu.back()) mu.push_back(m);
    }
    mu.front() = -1.0;
    mu.back() = 1.0;
  }

  std::vector<double> dcsca(mu.size(), 0.0);  // sum_s N_s <dC_sca/dOmega>, 1/(um sr)
  double g_mu_s = 0;
  for (const auto& s : spec.species) {
    if (s.volume_fraction <= 0) continue;
    MieEnsembleOptions eo;
    eo.lognormal_nodes = options.lognormal_nodes;
    const MieEnsemble e =
        mie_ensemble(s.n[band], s.k[band], out.host_n, s.size, out.wavelength_nm, mu, eo);
    const double number_density = s.volume_fraction / e.mean_volume_um3;
    const double mu_s = number_density * e.mean_csca_um2;
    out.mu_s_per_um += mu_s;
    out.mu_a_particles_per_um += number_density * e.mean_cabs_um2;
    g_mu_s += mu_s * e.g;
    for (size_t j = 0; j < mu.size(); ++j) dcsca[j] += mu_s * e.phase[j];
  }
  out.mu_a_per_um = out.mu_a_particles_per_um + out.mu_a_host_per_um;
  const double mu_t = out.mu_s_per_um + out.mu_a_per_um;
  out.albedo = mu_t > 0 ? out.mu_s_per_um / mu_t : 0.0;
  if (out.mu_s_per_um > 0) {
    out.g = g_mu_s / out.mu_s_per_um;
    out.phase = PhaseFunction::tabulated(mu, dcsca);
  } else {
    const double iso_mu[] = {-1.0, 1.0}, iso_p[] = {1.0, 1.0};
    out.phase = PhaseFunction::tabulated(iso_mu, iso_p);
  }
  return out;
}

FiberMedium build_fiber_medium(const FiberSpec& spec, std::span<const int> bands,
                               const MediumOptions& options, const ProgressCallback& progress) {
  std::vector<int> todo(bands.begin(), bands.end());
  if (todo.empty())
    for (int b = 0; b < kNumBands; ++b) todo.push_back(b);
  for (int b : todo)
    if (b < 0 || b >= kNumBands)
      throw Error("", "bands",
                  "band " + std::to_string(b) + " outside 0.." + std::to_string(kNumBands - 1));
  FiberMedium m;
  m.spec_name = spec.name;
  m.spec_hash = fiber_spec_hash_hex(spec);
  m.fiber_radius_um = spec.fiber_radius_um;
  m.bands.resize(todo.size());

  std::mutex report;
  uint64_t done = 0;
  std::atomic<bool> cancelled{false};
  parallel_for(todo.size(), options.threads, [&](uint64_t i) {
    if (cancelled.load()) return;
    m.bands[i] = compute_medium_band(spec, todo[i], options);
    std::lock_guard<std::mutex> lock(report);  // the callback need not be thread-safe
    const uint64_t d = ++done;
    if (progress && !progress({"medium", d, todo.size()})) cancelled.store(true);
  });
  if (cancelled.load()) throw Error("", "", "cancelled");
  return m;
}

MediumPlan plan_medium(const MediumRequest& request) {
  MediumPlan p;
  p.spec = load_fiber_spec(request.spec);
  for (double w : request.wavelengths_nm) {
    const double b = (w - kFirstBandNm) / kBandStepNm;
    const long bi = std::lround(b);
    if (std::abs(b - bi) > 1e-9 || bi < 0 || bi >= kNumBands) {
      char nm[32];
      std::snprintf(nm, sizeof nm, "%g", w);
      throw Error(
          "", "--wavelengths-nm",
          std::string("wavelength ") + nm + " nm is not a band centre (390, 400, ..., 710)");
    }
    p.bands.push_back(static_cast<int>(bi));
  }
  if (request.threads < 0) throw Error("", "--threads", "must be >= 0");
  p.options.threads = request.threads;
  return p;
}

nlohmann::json run_medium(const MediumPlan& p, const ProgressCallback& progress) {
  const FiberMedium m = build_fiber_medium(p.spec, p.bands, p.options, progress);
  nlohmann::json out = {{"name", m.spec_name},
                        {"hash", m.spec_hash},
                        {"fiber_radius_um", m.fiber_radius_um},
                        {"roughness",
                         {{"distribution", microfacet_model_name(p.spec.roughness_distribution)},
                          {"alpha", p.spec.roughness_alpha}}}};
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& b : m.bands)
    arr.push_back({{"wavelength_nm", b.wavelength_nm},
                   {"host_n", b.host_n},
                   {"mu_s_per_um", b.mu_s_per_um},
                   {"mu_a_per_um", b.mu_a_per_um},
                   {"mu_a_host_per_um", b.mu_a_host_per_um},
                   {"mu_a_particles_per_um", b.mu_a_particles_per_um},
                   {"albedo", b.albedo},
                   {"g", b.g},
                   {"g_table", b.phase.mean_cosine()}});
  out["bands"] = arr;
  return out;
}

}  // namespace weft
