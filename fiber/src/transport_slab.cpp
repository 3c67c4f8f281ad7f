#include "weft/fiber/transport_slab.h"

#include <array>
#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

// Per-photon exit sums, split by face and by whether the photon scattered.
struct SlabExitRecorder {
  double top_unscattered = 0, top_scattered = 0, bottom_unscattered = 0, bottom_scattered = 0;

  void on_exit(const ExitEvent& e) {
    const bool scattered = e.scatterings > 0;
    if (e.boundary == SlabGeometry::kTop)
      (scattered ? top_scattered : top_unscattered) += e.weight;
    else
      (scattered ? bottom_scattered : bottom_unscattered) += e.weight;
  }
};

// The energy books and, beyond them, the exits split by face and by scattering: rb, rd, tb, td,
// tt in that order.
struct SlabTally {
  PhotonStats books;
  std::array<MeanAccumulator, 5> faces;

  SlabTally& operator+=(const SlabTally& o) {
    books += o.books;
    for (size_t k = 0; k < faces.size(); ++k) faces[k] += o.faces[k];
    return *this;
  }
};

}  // namespace

void SlabSetup::validate() const {
  medium.validate();
  options.validate();
  (void)SlabGeometry(thickness, n_above, n_below);
  if (!std::isfinite(incidence_rad) || incidence_rad < 0 || !(incidence_rad < kPi / 2))
    throw Error("", "incidence", "must lie in [0, 90) degrees");
  if (!std::isfinite(thickness) && !(medium.mu_a + medium.mu_s > 0))
    throw Error("", "thickness",
                "a semi-infinite slab needs mu_a + mu_s > 0 (light would travel without end)");
}

SlabResult simulate_slab(const SlabSetup& setup, const TaskBatch& batch) {
  setup.validate();
  const SlabTransport transport(SlabGeometry(setup.thickness, setup.n_above, setup.n_below),
                                setup.medium, setup.options);
  const Vec3 direction{std::sin(setup.incidence_rad), 0, -std::cos(setup.incidence_rad)};

  SlabTally total;
  const TaskBatchStatus status = run_batch<SlabTally>(
      photon_batch(batch),
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, SlabTally& tally) {
        for (uint64_t i = 0; i < count; ++i) {
          PhotonTally photon;
          SlabExitRecorder exits;
          transport.launch_external(SlabGeometry::kTop, Vec3{0, 0, 0}, direction, 1.0, rng, exits,
                                    photon);
          tally.books.add(photon);
          const double faces[5] = {exits.top_unscattered, exits.top_scattered,
                                   exits.bottom_unscattered, exits.bottom_scattered,
                                   exits.bottom_unscattered + exits.bottom_scattered};
          for (size_t k = 0; k < 5; ++k) tally.faces[k].add(faces[k]);
        }
      },
      [&](const SlabTally& t) { total += t; });

  SlabResult r;
  static_cast<PhotonFractions&>(r) = total.books.fractions();
  const uint64_t n = total.books.photons;
  MeanEstimate* faces[5] = {&r.rb, &r.rd, &r.tb, &r.td, &r.tt};
  for (size_t k = 0; k < 5; ++k) *faces[k] = total.faces[k].estimate(n);
  r.cancelled = status.cancelled;
  return r;
}

namespace {

void require_finite_slab_value(double v, const char* option, bool non_negative) {
  if (!std::isfinite(v)) throw Error("", option, "must be a finite number");
  if (non_negative && v < 0) throw Error("", option, "must be >= 0");
}

double parse_slab_thickness_mm(const std::string& text) {
  if (text == "inf" || text == "infinity") return std::numeric_limits<double>::infinity();
  const auto v = finite_number(text);
  if (!v) throw Error("", "--thickness-mm", "'" + text + "' is not a finite number or 'inf'");
  if (!(*v > 0)) throw Error("", "--thickness-mm", "must be > 0");
  return *v;
}

}  // namespace

SlabPlan plan_slab(const SlabRequest& o) {
  require_finite_slab_value(o.mua_per_mm, "--mua-per-mm", true);
  require_finite_slab_value(o.mus_per_mm, "--mus-per-mm", true);
  require_finite_slab_value(o.g, "--g", false);
  if (!(o.g > -1 && o.g < 1)) throw Error("", "--g", "must lie in (-1, 1)");
  for (auto [v, name] : {std::pair{o.n_slab, "--n-slab"}, std::pair{o.n_above, "--n-above"},
                         std::pair{o.n_below, "--n-below"}}) {
    require_finite_slab_value(v, name, true);
    if (!(v >= 1e-6)) throw Error("", name, "refractive index must be > 0");
  }
  require_finite_slab_value(o.incidence_deg, "--incidence-deg", true);
  if (!(o.incidence_deg < 90)) throw Error("", "--incidence-deg", "must lie in [0, 90)");
  if (o.photons < 1) throw Error("", "--photons", "must be >= 1");
  if (o.threads < 0) throw Error("", "--threads", "must be >= 0 (0: all cores)");
  if (o.photons_per_task < 1) throw Error("", "--photons-per-task", "must be >= 1");

  SlabPlan p;
  p.request = o;
  SlabSetup& s = p.setup;
  s.medium.mu_a = o.mua_per_mm;
  s.medium.mu_s = o.mus_per_mm;
  s.medium.n = o.n_slab;
  s.medium.phase = PhaseFunction::henyey_greenstein(o.g);
  s.thickness = parse_slab_thickness_mm(o.thickness_mm);
  s.n_above = o.n_above;
  s.n_below = o.n_below;
  s.incidence_rad = deg_to_rad(o.incidence_deg);
  s.options.mode = o.analog ? WeightMode::analog : WeightMode::implicit_capture;
  if (!std::isfinite(s.thickness) && !(s.medium.mu_a + s.medium.mu_s > 0))
    throw Error("", "--thickness-mm", "a semi-infinite slab needs --mua-per-mm + --mus-per-mm > 0");
  p.batch.items = static_cast<uint64_t>(o.photons);
  p.batch.seed = o.seed;
  p.batch.threads = o.threads;
  p.batch.items_per_task = static_cast<uint64_t>(o.photons_per_task);
  return p;
}

std::vector<std::pair<const char*, MeanEstimate>> slab_quantities(const SlabResult& r) {
  return {{"rsp", r.specular},
          {"rb", r.rb},
          {"rd", r.rd},
          {"tb", r.tb},
          {"td", r.td},
          {"tt", r.tt},
          {"absorbed", r.absorbed},
          {"roulette", r.roulette},
          {"lost", r.lost}};
}

SlabOutcome run_slab(const SlabPlan& p, const ProgressCallback& progress) {
  const SlabRequest& o = p.request;
  TaskBatch batch = p.batch;
  batch.progress = progress;
  SlabOutcome out;
  const SlabResult& r = out.result = simulate_slab(p.setup, batch);
  nlohmann::json& j = out.summary;
  for (const auto& [key, e] : slab_quantities(r)) {
    j[key] = e.mean;
    j[std::string(key) + "_err"] = e.std_error;
  }
  j["energy_imbalance"] = r.energy_imbalance;
  j["photons"] = r.photons;
  j["photons_requested"] = batch.items;
  j["scatterings"] = r.scatterings;
  j["internal_reflections"] = r.reflections;
  j["cancelled"] = r.cancelled;
  j["inputs"] = {{"mua_per_mm", o.mua_per_mm},
                 {"mus_per_mm", o.mus_per_mm},
                 {"g", o.g},
                 {"n_slab", o.n_slab},
                 {"n_above", o.n_above},
                 {"n_below", o.n_below},
                 {"thickness_mm", o.thickness_mm},
                 {"incidence_deg", o.incidence_deg},
                 {"seed", o.seed},
                 {"photons_per_task", o.photons_per_task},
                 {"mode", o.analog ? "analog" : "implicit_capture"}};
  return out;
}

}  // namespace weft
