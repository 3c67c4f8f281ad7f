// weft bake fiber: a fiber spec (file or preset) -> fiber BSDF table (.exr) + JSON summary.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/materials/fabric/fiber_spec.h"
#include "weft/materials/fabric/fiber_table_bake.h"

namespace weft::cli {

void add_bake_command(CLI::App& app, Commands& commands) {
  auto* bake = app.add_subcommand("bake", "Bake BSDF tables from physical specs");
  bake->require_subcommand(1);
  add_bake_fabric_command(*bake, commands);

  struct Options {
    std::string spec;
    std::string output;
    uint64_t photons = FiberTableBakeOptions{}.photons_per_band;
    int resolution = FiberTableBakeOptions{}.resolution;
    std::string bands = "spectral";
    std::string route = "direct";
    uint64_t seed = FiberTableBakeOptions{}.seed;
    uint64_t passes = FiberTableBakeOptions{}.passes;
    int threads = 0;
    bool json = false;
    bool quiet = false;
  };
  auto opt = std::make_shared<Options>();
  auto* fiber = bake->add_subcommand(
      "fiber", "Fiber BSDF table: Mie medium -> photon transport in the fiber -> table");
  fiber
      ->add_option(
          "spec", opt->spec,
          "fiber spec JSON file, or a preset name (" +
              [] {
                std::string s;
                for (const auto& n : fiber_preset_names()) s += (s.empty() ? "" : ", ") + n;
                return s;
              }() +
              ")")
      ->required();
  fiber->add_option("-o,--output", opt->output, "output table (.exr)")->required();
  fiber->add_option("--photons", opt->photons, "photons per band")
      ->check(CLI::Range(uint64_t{1}, kMaxPhotonsPerBand));
  fiber
      ->add_option("--resolution", opt->resolution,
                   "bins per side of the equal-area square per direction")
      ->check(CLI::Range(2, TabulatedBsdfTable::kMaxResolution));
  fiber
      ->add_option("--bands", opt->bands,
                   "spectral (33 bands, 390-710 nm) or rgb (linear sRGB, D65)")
      ->check(CLI::IsMember({"spectral", "rgb"}));
  fiber->add_option("--route", opt->route, "direct (parallel beam) or bssrdf (the paper's route)")
      ->check(CLI::IsMember({"direct", "bssrdf"}));
  fiber->add_option("--seed", opt->seed, "random seed");
  fiber
      ->add_option("--passes", opt->passes,
                   "passes over all bands (an interrupted bake keeps finished passes)")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 20));
  fiber->add_option("--threads", opt->threads, "threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  fiber->add_flag("--json", opt->json, "print the summary as JSON");
  fiber->add_flag("--quiet", opt->quiet, "no progress bar");

  commands.push_back(
      {fiber, [opt] {
         TabulatedBsdfTable::check_output_path(opt->output, "--output");
         const FiberSpec spec = load_fiber_spec(opt->spec);
         FiberTableBakeOptions o;
         o.resolution = opt->resolution;
         o.photons_per_band = opt->photons;
         o.seed = opt->seed;
         o.threads = opt->threads;
         o.spectral = opt->bands == "spectral";
         o.route = opt->route == "direct" ? FiberBakeRoute::kDirect : FiberBakeRoute::kBssrdf;
         o.passes = opt->passes;
         check_memory(fiber_table_bake_bytes(o), "", "--resolution",
                      "a bake at resolution " + std::to_string(o.resolution));
         const unsigned cores = o.threads > 0 ? o.threads : std::thread::hardware_concurrency();
         check_long_work(
             static_cast<double>(o.photons_per_band) * kNumBands * kMinSecondsPerPhoton /
                 std::max(1u, cores),
             "", "--photons", std::to_string(o.photons_per_band) + " photons per band",
             "0.5 us per photon per core at least, " + std::to_string(cores) + " cores");
         const auto start = std::chrono::steady_clock::now();
         FiberTableBakeResult r = bake_fiber_table(spec, o, progress_bar(opt->quiet));
         const double seconds =
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
         r.table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
         r.table.write_exr(opt->output);

         nlohmann::json bands = nlohmann::json::array();
         for (const auto& b : r.bands)
           bands.push_back({{"wavelength_nm", b.wavelength_nm},
                            {"mu_s_per_um", b.mu_s_per_um},
                            {"mu_a_per_um", b.mu_a_per_um},
                            {"g", b.g},
                            {"photons", b.photons},
                            {"surface_reflected", b.surface_fraction},
                            {"albedo", b.exit_fraction},
                            {"absorbed", b.absorbed_fraction},
                            {"lost", b.lost_fraction},
                            {"roulette_net", b.roulette_net},
                            {"surface_sampling_excess", b.surface_sampling_excess},
                            {"energy_balance", b.energy_balance},
                            {"table_energy", b.energy_table}});
         nlohmann::json j = {{"output", opt->output},
                             {"spec", spec.name},
                             {"spec_hash", fiber_spec_hash_hex(spec)},
                             {"resolution", opt->resolution},
                             {"bands", opt->bands},
                             {"route", opt->route},
                             {"photons", r.photons},
                             {"scattering_events", r.scattering_events},
                             {"seconds", seconds},
                             {"events_per_s", seconds > 0 ? r.scattering_events / seconds : 0.0},
                             {"photons_per_s", seconds > 0 ? r.photons / seconds : 0.0},
                             {"interrupted", r.cancelled},
                             {"rgb_negative_clipped", r.rgb_negative_clipped},
                             {"per_band", bands}};
         if (opt->json) {
           std::cout << j.dump(2) << "\n";
         } else {
           std::printf("baked %s (%s) -> %s\n", spec.name.c_str(),
                       fiber_spec_hash_hex(spec).c_str(), opt->output.c_str());
           std::printf("%llu photons, %llu scattering events in %.1f s (%.3g events/s)%s\n",
                       static_cast<unsigned long long>(r.photons),
                       static_cast<unsigned long long>(r.scattering_events), seconds,
                       seconds > 0 ? r.scattering_events / seconds : 0.0,
                       r.cancelled ? "  [interrupted: table holds the finished passes]" : "");
           std::printf("  nm    mu_s/um   mu_a/um    g     surface  albedo  absorbed  balance\n");
           for (const auto& b : r.bands)
             std::printf("  %3.0f  %8.4f  %8.5f  %5.3f  %6.4f  %6.4f  %6.4f  %6.4f\n",
                         b.wavelength_nm, b.mu_s_per_um, b.mu_a_per_um, b.g, b.surface_fraction,
                         b.exit_fraction, b.absorbed_fraction, b.energy_balance);
         }
         if (r.cancelled) std::fprintf(stderr, "weft: interrupted; wrote the finished passes\n");
         return r.cancelled ? 130 : 0;
       }});
}

}  // namespace weft::cli
