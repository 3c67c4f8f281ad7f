// weft slab: MCML-style reflectance and transmittance of a plane-parallel slab (Henyey-Greenstein
// scattering, Fresnel boundaries) for validating the photon transport engine.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fiber/transport_slab.h"

namespace weft::cli {
namespace {

struct SlabOptions {
  double mua_per_mm = 0, mus_per_mm = 0, g = 0, n_slab = 1, n_above = 1, n_below = 1;
  std::string thickness_mm;
  double incidence_deg = 0;
  int64_t photons = 0;
  uint64_t seed = 0;
  int threads = 0;
  int64_t photons_per_task = 4096;
  bool analog = false, json = false, quiet = false;
};

void require_finite(double v, const char* option, bool non_negative) {
  if (!std::isfinite(v)) throw Error("", option, "must be a finite number");
  if (non_negative && v < 0) throw Error("", option, "must be >= 0");
}

double parse_thickness_mm(const std::string& text) {
  if (text == "inf" || text == "infinity") return std::numeric_limits<double>::infinity();
  const auto v = finite_number(text);
  if (!v) throw Error("", "--thickness-mm", "'" + text + "' is not a finite number or 'inf'");
  if (!(*v > 0)) throw Error("", "--thickness-mm", "must be > 0");
  return *v;
}

SlabSetup make_setup(const SlabOptions& o) {
  require_finite(o.mua_per_mm, "--mua-per-mm", true);
  require_finite(o.mus_per_mm, "--mus-per-mm", true);
  require_finite(o.g, "--g", false);
  if (!(o.g > -1 && o.g < 1)) throw Error("", "--g", "must lie in (-1, 1)");
  for (auto [v, name] : {std::pair{o.n_slab, "--n-slab"}, std::pair{o.n_above, "--n-above"},
                         std::pair{o.n_below, "--n-below"}}) {
    require_finite(v, name, true);
    if (!(v >= 1e-6)) throw Error("", name, "refractive index must be > 0");
  }
  require_finite(o.incidence_deg, "--incidence-deg", true);
  if (!(o.incidence_deg < 90)) throw Error("", "--incidence-deg", "must lie in [0, 90)");
  if (o.photons < 1) throw Error("", "--photons", "must be >= 1");
  if (o.threads < 0) throw Error("", "--threads", "must be >= 0 (0: all cores)");
  if (o.photons_per_task < 1) throw Error("", "--photons-per-task", "must be >= 1");

  SlabSetup s;
  s.medium.mu_a = o.mua_per_mm;
  s.medium.mu_s = o.mus_per_mm;
  s.medium.n = o.n_slab;
  s.medium.phase = PhaseFunction::henyey_greenstein(o.g);
  s.thickness = parse_thickness_mm(o.thickness_mm);
  s.n_above = o.n_above;
  s.n_below = o.n_below;
  s.incidence_rad = deg_to_rad(o.incidence_deg);
  s.options.mode = o.analog ? WeightMode::analog : WeightMode::implicit_capture;
  if (!std::isfinite(s.thickness) && !(s.medium.mu_a + s.medium.mu_s > 0))
    throw Error("", "--thickness-mm", "a semi-infinite slab needs --mua-per-mm + --mus-per-mm > 0");
  return s;
}

int run_slab(const SlabOptions& o, const RunLimits& limits) {
  const SlabSetup setup = make_setup(o);
  TaskBatch batch;
  batch.items = static_cast<uint64_t>(o.photons);
  batch.seed = o.seed;
  batch.threads = o.threads;
  batch.items_per_task = static_cast<uint64_t>(o.photons_per_task);
  batch.progress = progress_bar(limits, o.quiet);
  const SlabResult r = simulate_slab(setup, batch);

  const std::pair<const char*, MeanEstimate> values[] = {{"rsp", r.specular},
                                                         {"rb", r.rb},
                                                         {"rd", r.rd},
                                                         {"tb", r.tb},
                                                         {"td", r.td},
                                                         {"tt", r.tt},
                                                         {"absorbed", r.absorbed},
                                                         {"roulette", r.roulette},
                                                         {"lost", r.lost}};
  if (o.json) {
    nlohmann::json j;
    for (const auto& [key, e] : values) {
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
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("%-9s %12s %12s\n", "quantity", "value", "std_error");
    for (const auto& [key, e] : values)
      std::printf("%-9s %12.6f %12.6f\n", key, e.mean, e.std_error);
    std::printf("photons %llu of %llu, scatterings %llu%s\n",
                static_cast<unsigned long long>(r.photons),
                static_cast<unsigned long long>(batch.items),
                static_cast<unsigned long long>(r.scatterings), r.cancelled ? " (cancelled)" : "");
  }
  if (r.cancelled) {
    std::fprintf(stderr, "weft slab: cancelled after %llu photons; results above cover those\n",
                 static_cast<unsigned long long>(r.photons));
    return 130;
  }
  return 0;
}

}  // namespace

void add_slab_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<SlabOptions>();
  auto* sub = app.add_subcommand(
      "slab", "Monte Carlo reflectance/transmittance of a plane-parallel slab (MCML-style check)");
  sub->add_option("--mua-per-mm", o->mua_per_mm, "absorption coefficient [1/mm]")->required();
  sub->add_option("--mus-per-mm", o->mus_per_mm, "scattering coefficient [1/mm]")->required();
  sub->add_option("--g", o->g, "Henyey-Greenstein asymmetry, in (-1, 1)")->required();
  sub->add_option("--n-slab", o->n_slab, "refractive index of the slab")->required();
  sub->add_option("--n-above", o->n_above, "refractive index above the slab")
      ->capture_default_str();
  sub->add_option("--n-below", o->n_below, "refractive index below the slab")
      ->capture_default_str();
  sub->add_option("--thickness-mm", o->thickness_mm, "slab thickness [mm], or 'inf'")->required();
  sub->add_option("--incidence-deg", o->incidence_deg, "beam angle from the normal [deg]")
      ->capture_default_str();
  sub->add_option("--photons", o->photons, "photons to trace")->required();
  sub->add_option("--seed", o->seed, "random seed")->required();
  sub->add_option("--threads", o->threads, "threads (0: all cores)")->capture_default_str();
  sub->add_option("--photons-per-task", o->photons_per_task,
                  "photons per random stream (changing it changes the bits)")
      ->capture_default_str();
  sub->add_flag("--analog", o->analog, "analog absorption instead of implicit capture");
  sub->add_flag("--json", o->json, "print JSON");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  commands.push_back({sub, [o](const RunLimits& l) { return run_slab(*o, l); }});
}

}  // namespace weft::cli
