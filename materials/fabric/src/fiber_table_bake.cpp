#include "weft/materials/fabric/fiber_table_bake.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/fabric/fiber_bake.h"
#include "weft/materials/fabric/medium.h"
#include "weft/materials/fabric/transport.h"

namespace weft {

SurfaceAlbedoTable::SurfaceAlbedoTable(MicrofacetModel model, double alpha, double ior, int nodes,
                                       int samples_per_side) {
  const CookTorranceBsdf ct{{model, alpha}, ior, Rgb(1.0)};
  albedo_.resize(nodes);
  for (int k = 0; k < nodes; ++k) {
    const double cos_t = std::max(1e-4, static_cast<double>(k) / (nodes - 1));
    const Vec3 w{safe_sqrt(1 - cos_t * cos_t), 0, cos_t};
    double sum = 0;
    for (int a = 0; a < samples_per_side; ++a)
      for (int b = 0; b < samples_per_side; ++b) {
        const Vec2 u{(a + 0.5) / samples_per_side, (b + 0.5) / samples_per_side};
        if (const auto s = ct.sample(w, u, 0.5)) sum += s->weight.r;
      }
    albedo_[k] = sum / (samples_per_side * samples_per_side);
  }
}

double SurfaceAlbedoTable::operator()(double cos_theta) const {
  const double x = std::clamp(cos_theta, 0.0, 1.0) * (albedo_.size() - 1);
  const size_t i = std::min(static_cast<size_t>(x), albedo_.size() - 2);
  const double t = x - i;
  return (1 - t) * albedo_[i] + t * albedo_[i + 1];
}

FiberBandPhysics fiber_band_physics(const FiberSpec& spec, const MediumBand& mb,
                                    uint64_t max_events_per_photon,
                                    std::shared_ptr<const SurfaceAlbedoTable> albedo) {
  FiberBandPhysics ph;
  ph.geometry = FiberGeometry{spec.fiber_radius_um, mb.host_n, 1.0};
  auto ct = std::make_shared<const CookTorranceBsdf>(
      CookTorranceBsdf{{spec.roughness_distribution, spec.roughness_alpha}, mb.host_n, Rgb(1.0)});
  if (!albedo)
    albedo = std::make_shared<const SurfaceAlbedoTable>(spec.roughness_distribution,
                                                        spec.roughness_alpha, mb.host_n);
  ph.surface.sample = [ct](const Vec3& w_light, Vec2 u, double u_lobe, Vec3* w_out,
                           double* weight) {
    // Cook-Torrance is reciprocal: sampling the view direction given the light one uses the same
    // routine with the roles swapped; the weight is f cos(out) / pdf.
    const auto smp = ct->sample(w_light, u, u_lobe);
    if (!smp || !(smp->wi.z > 0)) return false;
    *w_out = smp->wi;
    *weight = smp->weight.r;
    return true;
  };
  ph.surface.albedo = [albedo](double c) { return (*albedo)(c); };
  TransportOptions topt;
  topt.max_events = max_events_per_photon;
  // Leaving the fiber, light meets the same rough boundary it entered through: transmitted with
  // 1 - (the surface lobe's albedo at the outside angle), as on entry.
  topt.exit_reflectance = [albedo](double cos_outside) { return (*albedo)(cos_outside); };
  auto transport = std::make_shared<const CylinderTransport>(
      CylinderGeometry(spec.fiber_radius_um, 1.0),
      TransportMedium{mb.mu_a_per_um, mb.mu_s_per_um, mb.host_n, mb.phase}, topt);
  ph.tracer = [transport](const Vec3& p, const Vec3& d, double w, Rng& rng,
                          const FiberExitSink& sink) {
    struct Forward {
      const FiberExitSink* sink;
      void on_exit(const ExitEvent& e) { (*sink)(FiberExit{e.position, e.direction, e.weight}); }
    } recorder{&sink};
    PhotonTally tally;
    // The entry point sits on the wall; nudge it inside so rounding cannot put it outside.
    transport->launch_internal(p * (1 - 1e-12), d, w, rng, recorder, tally);
    return FiberTraceResult{tally.scatterings, tally.absorbed,
                            tally.roulette_loss - tally.roulette_gain, tally.lost};
  };
  return ph;
}

namespace {

void validate(const FiberTableBakeOptions& o) {
  if (o.resolution < 2 || o.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [2, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (o.photons_per_band == 0) throw Error("", "photons", "must be positive");
  if (o.max_events_per_photon == 0) throw Error("", "max_events_per_photon", "must be positive");
}

}  // namespace

FiberTableBakeResult bake_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& o,
                                      const ProgressCallback& progress) {
  validate(o);
  MediumOptions medium_options;
  medium_options.threads = o.threads;
  const FiberMedium medium = build_fiber_medium(spec, {}, medium_options);

  const int R = o.resolution;
  const size_t cells = static_cast<size_t>(R) * R;
  const auto bin_areas = cosine_weighted_bin_areas(R);

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
              ? bake_fiber_band_direct(ph.geometry, ph.surface, ph.tracer, settings, band_progress)
              : bake_fiber_band_bssrdf(ph.geometry, ph.surface, ph.tracer, settings, BssrdfGrid{},
                                       band_progress);
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
      band_f[band].resize(cells * cells);
      for (size_t i = 0; i < cells; ++i)
        for (size_t k = 0; k < cells; ++k)
          band_f[band][i * cells + k] =
              st.weighted_sum[i * cells + k] * inv / (bin_areas[i] * bin_areas[k]);
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
  const auto& w = srgb_band_weights_d65();
  for (size_t k = 0; k < cells * cells; ++k) {
    if (o.spectral) {
      for (int b = 0; b < kNumBands; ++b)
        table.values[k * kNumBands + b] = static_cast<float>(band_f[b][k]);
    } else {
      Rgb rgb;
      for (int b = 0; b < kNumBands; ++b) rgb += w[b] * band_f[b][k];
      for (double* c : {&rgb.r, &rgb.g, &rgb.b}) {
        if (*c < 0) {
          result.rgb_negative_clipped = std::max(result.rgb_negative_clipped, -*c);
          *c = 0;
        }
      }
      table.values[k * 3 + 0] = static_cast<float>(rgb.r);
      table.values[k * 3 + 1] = static_cast<float>(rgb.g);
      table.values[k * 3 + 2] = static_cast<float>(rgb.b);
    }
  }
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
