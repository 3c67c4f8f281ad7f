#include "weft/materials/fabric/fiber_table_bake.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/materials/fabric/fiber_bake.h"
#include "weft/materials/fabric/medium.h"

namespace weft {

namespace {

void validate(const FiberTableBakeOptions& o) {
  if (o.resolution < 2 || o.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [2, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (o.photons_per_band == 0) throw Error("", "photons", "must be positive");
  if (o.max_events_per_photon == 0) throw Error("", "max_events_per_photon", "must be positive");
}

}  // namespace

double fiber_table_bake_bytes(const FiberTableBakeOptions& o) {
  const double cells = DirectionGrid{std::clamp(o.resolution, 1, 1 << 12)}.bins();
  const double pairs = cells * cells;
  const int channels = o.spectral ? kNumBands : 3;
  // weighted_sum and band_f for every band, one band's table and mean_sum in flight, the table.
  return pairs *
         (2.0 * kNumBands * sizeof(double) + 2.0 * sizeof(double) + channels * sizeof(float));
}

FiberTableBakeResult bake_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& o,
                                      const ProgressCallback& progress) {
  validate(o);
  MediumOptions medium_options;
  medium_options.threads = o.threads;
  const FiberMedium medium = build_fiber_medium(spec, {}, medium_options);

  const int R = o.resolution;
  const size_t cells = static_cast<size_t>(DirectionGrid{R}.bins());

  // Per band: the physics, and running sums over passes.
  struct BandState {
    FiberBandPhysics physics;
    std::vector<double> weighted_sum;  // photon-weighted sum of per-pass cell sums
    double surface = 0, exit = 0, absorbed = 0, roulette = 0, lost = 0, excess = 0, energy = 0;
    uint64_t photons = 0, events = 0;
  };
  std::vector<BandState> states(kNumBands);
  std::map<double, std::shared_ptr<const SurfaceAlbedoTable>> albedo_by_ior;
  for (int band = 0; band < kNumBands; ++band) {
    auto& albedo = albedo_by_ior[medium.bands[band].host_n];
    if (!albedo)
      albedo = std::make_shared<const SurfaceAlbedoTable>(
          spec.roughness_distribution, spec.roughness_alpha, medium.bands[band].host_n);
    states[band].physics =
        fiber_band_physics(spec, medium.bands[band], o.max_events_per_photon, albedo);
    states[band].weighted_sum.assign(cells * cells, 0.0);
  }

  // Photons are traced in passes over all bands, so an interrupted bake still has every band,
  // each with the photons of the passes it finished (the table records how many).
  const uint64_t passes = std::clamp<uint64_t>(o.passes, 1, o.photons_per_band);
  const uint64_t total_units = o.photons_per_band * kNumBands;
  uint64_t units_done = 0;
  bool stop_requested = false;
  FiberTableBakeResult result;
  for (uint64_t pass = 0; pass < passes && !result.cancelled; ++pass) {
    const uint64_t first = o.photons_per_band * pass / passes;
    const uint64_t count = o.photons_per_band * (pass + 1) / passes - first;
    for (int band = 0; band < kNumBands && !result.cancelled; ++band) {
      BandState& st = states[band];
      const FiberBandPhysics& ph = st.physics;
      FiberBakeSettings settings;
      settings.resolution = R;
      settings.photons = count;
      // Disjoint random streams per (seed, pass, band).
      settings.seed = mix64(mix64(o.seed) ^ (pass * kNumBands + static_cast<uint64_t>(band)));
      settings.threads = o.threads;
      const uint64_t base = units_done;
      // A stop request may arrive after a band's last task: remember it for the loops here.
      ProgressCallback band_progress = [&](const ProgressUpdate& u) {
        if (progress && !progress({"photons", base + u.done, total_units})) stop_requested = true;
        return !stop_requested;
      };
      const FiberBandTable t =
          o.route == FiberBakeRoute::kDirect
              ? bake_fiber_band_direct(ph, settings, band_progress)
              : bake_fiber_band_bssrdf(ph, settings, BssrdfRouteSettings{}, band_progress);
      const double n = static_cast<double>(t.photons);
      for (size_t k = 0; k < st.weighted_sum.size(); ++k)
        st.weighted_sum[k] += t.weighted_sum[k] * n;
      st.surface += t.surface_fraction * n;
      st.exit += t.exit_fraction * n;
      st.lost += t.lost_fraction * n;
      st.absorbed += t.absorbed_fraction * n;
      st.roulette += t.roulette_net * n;
      st.excess += t.surface_sampling_excess * n;
      st.energy += fiber_table_energy(t) / kPi * n;
      st.photons += t.photons;
      st.events += t.scattering_events;
      units_done += t.photons;
      result.photons += t.photons;
      result.scattering_events += t.scattering_events;
      result.cancelled = t.cancelled || stop_requested;
    }
  }

  std::vector<std::vector<double>> band_f(kNumBands);
  for (int band = 0; band < kNumBands; ++band) {
    BandState& st = states[band];
    const MediumBand& mb = medium.bands[band];
    FiberBandSummary s;
    s.band = band;
    s.wavelength_nm = band_wavelength_nm(band);
    s.mu_s_per_um = mb.mu_s_per_um;
    s.mu_a_per_um = mb.mu_a_per_um;
    s.g = mb.g;
    s.photons = st.photons;
    s.scattering_events = st.events;
    if (st.photons > 0) {
      const double inv = 1.0 / static_cast<double>(st.photons);
      s.surface_fraction = st.surface * inv;
      s.exit_fraction = st.exit * inv;
      s.lost_fraction = st.lost * inv;
      s.absorbed_fraction = st.absorbed * inv;
      s.roulette_net = st.roulette * inv;
      s.surface_sampling_excess = st.excess * inv;
      s.energy_balance = s.exit_fraction + s.absorbed_fraction + s.roulette_net + s.lost_fraction -
                         s.surface_sampling_excess;
      s.energy_table = st.energy * inv;
      // The photon-weighted mean of the passes' sums, then cell averages.
      std::vector<double> mean_sum(st.weighted_sum.size());
      for (size_t k = 0; k < mean_sum.size(); ++k) mean_sum[k] = st.weighted_sum[k] * inv;
      band_f[band] = TabulatedBsdfTable::averages_from_weighted_sums(R, mean_sum);
    }
    result.bands.push_back(s);
  }
  uint64_t min_photons = states[0].photons;
  for (const auto& st : states) min_photons = std::min(min_photons, st.photons);
  if (min_photons == 0) {
    throw Error("", "photons",
                "interrupted before every band had photons: no table written (let the first of " +
                    std::to_string(passes) + " passes finish)");
  }

  TabulatedBsdfTable& table = result.table;
  table.resolution = R;
  table.kind = "fiber";
  table.channels = o.spectral ? kNumBands : 3;
  table.values.assign(cells * cells * table.channels, 0.0f);
  GamutClip gamut;
  for (size_t k = 0; k < cells * cells; ++k) {
    if (o.spectral) {
      for (int b = 0; b < kNumBands; ++b)
        table.values[k * kNumBands + b] = static_cast<float>(band_f[b][k]);
    } else {
      Rgb rgb = bands_to_linear_srgb([&](int b) { return band_f[b][k]; });
      gamut.clip(rgb);
      table.values[k * 3 + 0] = static_cast<float>(rgb.r);
      table.values[k * 3 + 1] = static_cast<float>(rgb.g);
      table.values[k * 3 + 2] = static_cast<float>(rgb.b);
    }
  }
  result.rgb_negative_clipped = gamut.largest;
  table.metadata = {
      {"spec_hash", fiber_spec_hash_hex(spec)},
      {"spec_name", spec.name},
      {"photons", std::to_string(min_photons)},
      {"photons_requested", std::to_string(o.photons_per_band)},
      {"interrupted", result.cancelled ? "yes" : "no"},
      {"seed", std::to_string(o.seed)},
      {"route", o.route == FiberBakeRoute::kDirect ? "direct" : "bssrdf"},
      {"fiber_radius_um", std::to_string(spec.fiber_radius_um)},
      {"roughness", std::string(microfacet_model_name(spec.roughness_distribution)) + " alpha " +
                        std::to_string(spec.roughness_alpha)},
      {"definition",
       "f = L_o / (E |cos theta_i|); cosine-weighted cell averages (docs/fiber-bsdf.md)"},
  };
  if (!o.spectral)
    table.metadata["rgb_negative_clipped"] = std::to_string(result.rgb_negative_clipped);
  table.validate("");
  return result;
}

}  // namespace weft
