#include "weft/fiber/fiber_table_bake.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/spectrum.h"
#include "weft/fiber/fiber_bake.h"
#include "weft/fiber/medium.h"

namespace weft {

namespace {

void validate(const FiberTableBakeOptions& o) {
  if (o.resolution < 2 || o.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [2, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (o.photons_per_band == 0) throw Error("", "photons", "must be positive");
  if (o.max_events_per_photon == 0) throw Error("", "max_events_per_photon", "must be positive");
  if (o.weight_mode != WeightMode::implicit_capture &&
      o.weight_mode != WeightMode::absorption_weight)
    throw Error("", "weight_mode", "must be implicit_capture or absorption_weight");
  if (o.estimator != FiberExitEstimator::kPlain && o.route != FiberBakeRoute::kDirect)
    throw Error("", "estimator", "next-event estimation is for the direct route");
  if (o.entry != FiberEntrySampling::kRandom && o.route != FiberBakeRoute::kDirect)
    throw Error("", "entry", "a stratified entry is for the direct route");
  if (o.surface_samples < 1 || o.surface_samples > 1024)
    throw Error("", "surface_samples", "must lie in [1, 1024]");
  if (o.surface_lobe == FiberSurfaceLobe::kAnalytic && o.route != FiberBakeRoute::kDirect)
    throw Error("", "surface_lobe", "an analytic surface lobe is for the direct route");
}

void check_analytic_lobe(const FiberSpec& spec, const FiberTableBakeOptions& o) {
  if (o.surface_lobe == FiberSurfaceLobe::kAnalytic && spec.boundary != FiberBoundary::kSmooth)
    throw Error("", "surface_lobe",
                "an analytic surface lobe needs the smooth boundary (the rough dielectric's "
                "surface part is its microsurface walk, not one Cook-Torrance lobe)");
}

// A band's pass added to its running sums (weighted by the pass's photons).
void add_band_pass(FiberBandState& st, const FiberBandTable& t) {
  const double n = static_cast<double>(t.photons);
  for (size_t k = 0; k < st.weighted_sum.size(); ++k) st.weighted_sum[k] += t.weighted_sum[k] * n;
  st.surface += t.surface_fraction * n;
  st.exit += t.exit_fraction * n;
  st.lost += t.lost_fraction * n;
  st.absorbed += t.absorbed_fraction * n;
  st.roulette += t.roulette_net * n;
  st.excess += t.surface_sampling_excess * n;
  st.exit_excess += t.expected_exit_excess * n;
  st.energy += fiber_table_energy(t) / kPi * n;
  st.photons += t.photons;
  st.events += t.scattering_events;
}

// The progress of a pass whose bands run on several threads: each band counts its photons here,
// and only the thread that started the bake calls the caller's callback, so its calls come one at
// a time (a front end's need not be thread-safe) with a count that never goes back. A stop it
// returns is seen by every band at its next wave.
class BandPassProgress {
 public:
  BandPassProgress(const ProgressCallback& progress, uint64_t total_units)
      : progress_(progress), total_units_(total_units), caller_(std::this_thread::get_id()) {}

  void start_pass(uint64_t units_done) {
    units_done_ = units_done;
    traced_ = 0;
  }
  bool stopped() const { return stop_.load(); }

  // A band's callback: its photons so far (u.done) are added to the pass's count.
  ProgressCallback for_band() {
    return [this, last = uint64_t{0}](const ProgressUpdate& u) mutable {
      traced_ += u.done - last;
      last = u.done;
      if (progress_ && std::this_thread::get_id() == caller_ &&
          !progress_({"photons", units_done_ + traced_.load(), total_units_}))
        stop_ = true;
      return !stop_.load();
    };
  }

 private:
  const ProgressCallback& progress_;
  uint64_t total_units_ = 0, units_done_ = 0;
  std::thread::id caller_;
  std::atomic<uint64_t> traced_{0};
  std::atomic<bool> stop_{false};
};

}  // namespace

SurfaceLobe fiber_surface_lobe(const FiberSpec& spec, bool spectral) {
  SurfaceLobe lobe;
  lobe.distribution = {spec.roughness_distribution, spec.roughness_alpha};
  if (spectral) {
    for (int b = 0; b < kNumBands; ++b) lobe.ior.push_back(spec.host_n[b]);
  } else {
    for (double nm : {610.0, 550.0, 460.0})
      lobe.ior.push_back(
          spec.host_n[static_cast<int>(std::lround((nm - band_wavelength_nm(0)) / 10))]);
  }
  return lobe;
}

FiberTableBakeOptions fiber_bake_defaults(const FiberSpec& spec, FiberBakeRoute route) {
  FiberTableBakeOptions o;
  o.route = route;
  const bool smooth = spec.boundary == FiberBoundary::kSmooth;
  const bool direct = route == FiberBakeRoute::kDirect;
  if (!smooth || !direct) o.estimator = FiberExitEstimator::kPlain;
  if (!smooth) o.surface_samples = 1;
  if (!direct) o.entry = FiberEntrySampling::kRandom;
  return o;
}

double fiber_table_bake_bytes(const FiberTableBakeOptions& o) {
  const double cells = DirectionGrid{std::clamp(o.resolution, 1, 1 << 12)}.bins();
  const double pairs = cells * cells;
  const int channels = o.spectral ? kNumBands : 3;
  // weighted_sum and band_f for every band, one band's table and mean_sum in flight, the table.
  return pairs *
         (2.0 * kNumBands * sizeof(double) + 2.0 * sizeof(double) + channels * sizeof(float));
}

FiberBandsResult trace_fiber_bands(const FiberSpec& spec, const FiberTableBakeOptions& o,
                                   const FiberBandWork& work, const ProgressCallback& progress) {
  validate(o);
  if (work.first_band < 0 || work.last_band > kNumBands || work.first_band >= work.last_band)
    throw Error("", "bands", "band range must lie in [0, " + std::to_string(kNumBands) + ")");
  check_analytic_lobe(spec, o);
  const int nb = work.last_band - work.first_band;
  if (!work.start.empty() && work.start.size() != static_cast<size_t>(nb))
    throw Error("", "bands", "a resumed bake needs one state per band");
  std::vector<int> band_ids;
  for (int b = work.first_band; b < work.last_band; ++b) band_ids.push_back(b);
  MediumOptions medium_options;
  medium_options.threads = o.threads;
  const FiberMedium medium = build_fiber_medium(spec, band_ids, medium_options, progress);

  const int R = o.resolution;
  const size_t cells = static_cast<size_t>(DirectionGrid{R}.bins());
  // Photons are traced in passes over all bands, so an interrupted bake still has every band,
  // each with the photons of the passes it finished (the table records how many).
  const uint64_t passes = std::clamp<uint64_t>(o.passes, 1, o.photons_per_band);
  FiberBandsResult result;
  result.passes = passes;
  std::vector<FiberBandState>& states = result.bands;
  states = work.start.empty() ? std::vector<FiberBandState>(nb) : work.start;
  std::vector<FiberBandPhysics> physics(nb);
  std::map<double, std::shared_ptr<const SurfaceAlbedoTable>> albedo_by_ior;
  for (int i = 0; i < nb; ++i) {
    const MediumBand& mb = medium.bands[i];
    auto& albedo = albedo_by_ior[mb.host_n];
    if (!albedo && spec.boundary == FiberBoundary::kSmooth)
      albedo = std::make_shared<const SurfaceAlbedoTable>(spec.roughness_distribution,
                                                          spec.roughness_alpha, mb.host_n);
    physics[i] =
        fiber_band_physics(spec, mb, o.max_events_per_photon, albedo, o.weight_mode, o.estimator);
    if (o.surface_samples != 1 && spec.boundary != FiberBoundary::kSmooth)
      throw Error("", "surface_samples",
                  "the rough dielectric boundary draws one walk per photon, not lobe samples");
    physics[i].surface.samples = o.surface_samples;
    FiberBandState& st = states[i];
    st.mu_s_per_um = mb.mu_s_per_um, st.mu_a_per_um = mb.mu_a_per_um, st.g = mb.g;
    if (work.start.empty()) st.weighted_sum.assign(cells * cells, 0.0);
    if (st.weighted_sum.size() != cells * cells || st.passes_done > passes)
      throw Error("", "bands", "a resumed state does not fit this bake's resolution or passes");
  }

  const uint64_t total_units = o.photons_per_band * static_cast<uint64_t>(nb);
  uint64_t units_done = 0;
  for (const auto& st : states) units_done += st.photons;
  BandPassProgress pass_progress(progress, total_units);
  uint64_t first_pass = passes;
  for (const auto& st : states) first_pass = std::min(first_pass, st.passes_done);
  for (uint64_t pass = first_pass; pass < passes && !result.cancelled; ++pass) {
    const uint64_t first = o.photons_per_band * pass / passes;
    const uint64_t count = o.photons_per_band * (pass + 1) / passes - first;
    std::vector<int> todo;
    for (int i = 0; i < nb; ++i)
      if (states[i].passes_done <= pass) todo.push_back(i);
    pass_progress.start_pass(units_done);
    // The bands of a pass side by side, each on one thread: a band's pass is a few tasks (two at
    // the defaults, 4 096 and 2 154 photons), too few to share out, so one thread waited on the
    // other at every band. One thread per band leaves the bits as they were (each band's tasks
    // and their order are the same at any thread count). Fewer bands than threads (a shard of a
    // few bands) go one after another, each on every thread, as before.
    const bool side_by_side = todo.size() >= static_cast<size_t>(thread_count(o.threads));
    std::vector<std::optional<FiberBandTable>> tables(static_cast<size_t>(nb));
    parallel_for(todo.size(), side_by_side ? o.threads : 1, [&](uint64_t j) {
      const int i = todo[j];
      if (pass_progress.stopped()) return;
      FiberBakeSettings settings;
      settings.resolution = R;
      settings.photons = count;
      // Disjoint random streams per (seed, pass, band).
      const int band = work.first_band + i;
      settings.seed = mix64(mix64(o.seed) ^ (pass * kNumBands + static_cast<uint64_t>(band)));
      settings.threads = side_by_side ? 1 : o.threads;
      settings.entry = o.entry;
      settings.book_surface = o.surface_lobe == FiberSurfaceLobe::kSampled;
      const ProgressCallback band_progress = pass_progress.for_band();
      tables[i] =
          o.route == FiberBakeRoute::kDirect
              ? bake_fiber_band_direct(physics[i], settings, band_progress)
              : bake_fiber_band_bssrdf(physics[i], settings, BssrdfRouteSettings{}, band_progress);
    });
    for (const int i : todo) {
      if (!tables[i]) continue;  // not started: a stop came first
      add_band_pass(states[i], *tables[i]);
      units_done += tables[i]->photons;
      // A band whose photons were all traced has finished the pass, whenever the stop came.
      if (!tables[i]->cancelled) states[i].passes_done = pass + 1;
    }
    for (const int i : todo)
      if (states[i].passes_done <= pass) result.cancelled = true;
    if (pass_progress.stopped()) result.cancelled = true;
    if (!result.cancelled && work.on_pass) work.on_pass(states);
  }
  return result;
}

namespace {

// The header of a baked fiber table: what it is of and how it was baked (the options only where
// not their former defaults, so that tables baked before an option keep their header).
std::map<std::string, std::string> fiber_table_metadata(const FiberSpec& spec,
                                                        const FiberTableBakeOptions& o,
                                                        uint64_t min_photons, bool cancelled) {
  std::map<std::string, std::string> m = {
      {"spec_hash", fiber_spec_hash_hex(spec)},
      {"spec_name", spec.name},
      {"photons", std::to_string(min_photons)},
      {"photons_requested", std::to_string(o.photons_per_band)},
      {"interrupted", cancelled ? "yes" : "no"},
      {"seed", std::to_string(o.seed)},
      {"route", o.route == FiberBakeRoute::kDirect ? "direct" : "bssrdf"},
      {"fiber_radius_um", std::to_string(spec.fiber_radius_um)},
      {"roughness", std::string(microfacet_model_name(spec.roughness_distribution)) + " alpha " +
                        std::to_string(spec.roughness_alpha)},
      {"definition",
       "f = L_o / (E |cos theta_i|); cosine-weighted cell averages (docs/fiber-bsdf.md)"},
  };
  // Only when not the default, so tables of the paper's model keep their header.
  if (spec.boundary != FiberBoundary::kSmooth) m["boundary"] = fiber_boundary_name(spec.boundary);
  if (o.estimator != FiberExitEstimator::kPlain) {
    m["exit_estimator"] = fiber_exit_estimator_name(o.estimator);
    m["energy"] = "the walk's own exits";
  }
  if (o.mirror_fold) m["mirror_fold"] = "yes";
  if (o.surface_samples != 1) m["surface_samples"] = std::to_string(o.surface_samples);
  if (o.entry != FiberEntrySampling::kRandom) m["entry"] = fiber_entry_sampling_name(o.entry);
  return m;
}

// The analytic lobe's cells added to the table, and their energy to each band's (the table's
// energy per band, sum f D_i D_o / pi: the lobe's at the band's index).
void add_analytic_lobe(const FiberSpec& spec, const FiberTableBakeOptions& o,
                       TabulatedBsdfTable& table, std::vector<FiberBandSummary>& bands) {
  // One quadrature per band's lobe (bands of one index share its draws): the bands' energies,
  // and a spectral table's cells.
  const SurfaceLobe per_band = fiber_surface_lobe(spec, true);
  const std::vector<double> band_cells = per_band.cell_averages(table.grid(), o.threads);
  if (o.spectral)
    table.add_surface_lobe(per_band, o.threads, &band_cells);
  else
    table.add_surface_lobe(fiber_surface_lobe(spec, false), o.threads);
  const auto d = table.grid().cosine_weighted_areas();
  const size_t b = d.size(), nb = static_cast<size_t>(kNumBands);
  for (auto& s : bands) {
    const size_t band = static_cast<size_t>(s.band);
    double energy = 0;
    for (size_t k = 0; k < b * b; ++k) energy += band_cells[k * nb + band] * d[k / b] * d[k % b];
    s.energy_table += energy / kPi;
  }
}

}  // namespace

double fiber_bake_min_seconds_per_photon(const FiberTableBakeOptions& o) {
  return o.estimator == FiberExitEstimator::kNextEvent && o.surface_samples >= 4
             ? kMinSecondsPerNextEventPhoton
             : kMinSecondsPerPhoton;
}

double fiber_walk_energy_scale(const FiberBandState& st, FiberSurfaceLobe lobe) {
  // With the analytic lobe the sums hold the volume's exits alone.
  const double booked = lobe == FiberSurfaceLobe::kAnalytic ? st.exit - st.surface : st.exit;
  if (st.exit_excess == 0 || !(booked > 0)) return 1;
  return (booked - st.exit_excess) / booked;
}

std::vector<double> fiber_band_averages(const FiberBandState& st, int resolution, bool mirror_fold,
                                        double scale) {
  // The photon-weighted mean of the passes' sums, then cell averages.
  const double inv = 1.0 / static_cast<double>(st.photons);
  std::vector<double> mean_sum(st.weighted_sum.size());
  for (size_t k = 0; k < mean_sum.size(); ++k) mean_sum[k] = st.weighted_sum[k] * inv * scale;
  if (mirror_fold) mean_sum = fold_fiber_mirror_symmetry(resolution, mean_sum);
  return TabulatedBsdfTable::averages_from_weighted_sums(resolution, mean_sum);
}

FiberTableBakeResult bake_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& o,
                                      const ProgressCallback& progress) {
  const FiberBandsResult r = trace_fiber_bands(spec, o, FiberBandWork{}, progress);
  return finish_fiber_table(spec, o, r.bands, r.cancelled);
}

FiberTableBakeResult finish_fiber_table(const FiberSpec& spec, const FiberTableBakeOptions& o,
                                        const std::vector<FiberBandState>& states, bool cancelled) {
  validate(o);
  if (states.size() != static_cast<size_t>(kNumBands))
    throw Error("", "bands",
                "a table needs the states of all " + std::to_string(kNumBands) + " bands");
  const int R = o.resolution;
  const size_t cells = static_cast<size_t>(DirectionGrid{R}.bins());
  const uint64_t passes = std::clamp<uint64_t>(o.passes, 1, o.photons_per_band);
  FiberTableBakeResult result;
  result.cancelled = cancelled;
  std::vector<std::vector<double>> band_f(kNumBands);
  for (int band = 0; band < kNumBands; ++band) {
    const FiberBandState& st = states[band];
    if (st.weighted_sum.size() != cells * cells)
      throw Error("", "bands", "band " + std::to_string(band) + " has another resolution");
    result.photons += st.photons;
    result.scattering_events += st.events;
    FiberBandSummary s;
    s.band = band;
    s.wavelength_nm = band_wavelength_nm(band);
    s.mu_s_per_um = st.mu_s_per_um;
    s.mu_a_per_um = st.mu_a_per_um;
    s.g = st.g;
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
      s.expected_exit_excess = st.exit_excess * inv;
      s.energy_balance = s.exit_fraction + s.absorbed_fraction + s.roulette_net + s.lost_fraction -
                         s.surface_sampling_excess - s.expected_exit_excess;
      s.energy_scale = fiber_walk_energy_scale(st, o.surface_lobe);
      s.energy_table = st.energy * inv * s.energy_scale;
      band_f[band] = fiber_band_averages(st, R, o.mirror_fold, s.energy_scale);
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
  if (o.surface_lobe == FiberSurfaceLobe::kAnalytic) {
    check_analytic_lobe(spec, o);
    add_analytic_lobe(spec, o, table, result.bands);
  }
  table.metadata = fiber_table_metadata(spec, o, min_photons, result.cancelled);
  if (!o.spectral)
    table.metadata["rgb_negative_clipped"] = std::to_string(result.rgb_negative_clipped);
  table.validate("");
  return result;
}

}  // namespace weft
