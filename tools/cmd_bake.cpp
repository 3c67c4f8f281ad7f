// weft bake fiber: a fiber spec (file or preset) -> fiber BSDF table (.exr) + JSON summary.
// Binds the request's options (fiber/fiber_bake_request.h), runs its plan and prints.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/fabric/fiber_colour.h"
#include "weft/fiber/fiber_bake_request.h"
#include "weft/fiber/fiber_spec.h"

namespace weft::cli {

namespace {

struct FiberBakeCliOptions {
  FiberBakeRequest request;
  bool json = false, quiet = false;
};

// The summary of a bake (or of a merge of its shards) on stdout.
int report_fiber_bake(const nlohmann::json& j, bool json) {
  const bool cancelled = j["interrupted"].get<bool>();
  for (const auto& w : j.value("warnings", nlohmann::json::array()))
    std::fprintf(stderr, "weft: warning: %s\n", w.get<std::string>().c_str());
  if (json) {
    std::cout << j.dump(2) << "\n";
  } else {
    const auto photons = j["photons"].get<unsigned long long>();
    const auto events = j["scattering_events"].get<unsigned long long>();
    const double seconds = j["seconds"].get<double>();
    std::printf("baked %s (%s) -> %s\n", j["spec"].get<std::string>().c_str(),
                j["spec_hash"].get<std::string>().c_str(), j["output"].get<std::string>().c_str());
    if (j.contains("colour_match"))
      std::printf("%s\n", j["colour_match"]["note"].get<std::string>().c_str());
    std::printf("%llu photons, %llu scattering events in %.1f s (%.3g events/s)%s\n", photons,
                events, seconds, j["events_per_s"].get<double>(),
                cancelled ? "  [interrupted: table holds the finished passes]" : "");
    std::printf("  nm    mu_s/um   mu_a/um    g     surface  albedo  absorbed  balance\n");
    for (const auto& b : j["per_band"])
      std::printf("  %3.0f  %8.4f  %8.5f  %5.3f  %6.4f  %6.4f  %6.4f  %6.4f\n",
                  b["wavelength_nm"].get<double>(), b["mu_s_per_um"].get<double>(),
                  b["mu_a_per_um"].get<double>(), b["g"].get<double>(),
                  b["surface_reflected"].get<double>(), b["albedo"].get<double>(),
                  b["absorbed"].get<double>(), b["energy_balance"].get<double>());
  }
  if (cancelled) std::fprintf(stderr, "weft: interrupted; wrote the finished passes\n");
  return cancelled ? 130 : 0;
}

int run_bake_fiber(const FiberBakeCliOptions& o, const RunLimits& program) {
  FiberBakeRequest r = o.request;
  r.limits = quieted(program, o.quiet);
  r.option_prefix = "--";
  const ColouredFiberBakePlan coloured = plan_coloured_fiber_bake(
      r, [](const std::string& w) { std::fprintf(stderr, "weft: warning: %s\n", w.c_str()); });
  const FiberBakePlan& plan = coloured.fiber;
  FiberBakeHooks hooks;
  if (plan.bands.last > plan.bands.first) hooks.progress = progress_bar(r.limits, o.quiet);
  hooks.interrupted = interrupted;
  const FiberBakeOutcome out = run_coloured_fiber_bake(coloured, hooks);
  if (out.interrupted_before_work) {
    std::fprintf(stderr, "\nweft: interrupted before any photon; nothing was written\n");
    return 130;
  }
  if (!plan.shard.whole()) {
    if (out.cancelled) {
      std::fprintf(stderr, "\nweft: interrupted; no part written%s\n",
                   r.resume ? " (--resume continues from the last finished pass)" : "");
      return 130;
    }
    std::printf("bands %llu..%llu of %s (shard %u/%u) -> %s in %.1f s\n",
                static_cast<unsigned long long>(plan.bands.first),
                static_cast<unsigned long long>(plan.bands.last), plan.spec.name.c_str(),
                plan.shard.index, plan.shard.count, r.output.c_str(), out.seconds);
    return 0;
  }
  return report_fiber_bake(out.summary, o.json);
}

}  // namespace

int merge_fiber_bake(const JobPart& all, const std::string& output, bool json) {
  return report_fiber_bake(merge_fiber_bake_parts(all, output).summary, json);
}

namespace {

std::string fiber_preset_list() {
  std::string s;
  for (const auto& n : fiber_preset_names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// How many photons, of which bands and route, estimated and drawn how.
void add_fiber_sampling_options(CLI::App& fiber, FiberBakeRequest& r) {
  fiber.add_option("--photons", r.photons, "photons per band")
      ->check(CLI::Range(uint64_t{1}, kMaxPhotonsPerBand));
  fiber
      .add_option("--resolution", r.resolution,
                  "bins per side of the equal-area square per direction")
      ->check(CLI::Range(2, TabulatedBsdfTable::kMaxResolution));
  fiber.add_option("--bands", r.bands, "spectral (33 bands, 390-710 nm) or rgb (linear sRGB, D65)")
      ->check(CLI::IsMember(names_of(kFiberBakeBands)));
  fiber.add_option("--route", r.route, "direct (parallel beam) or bssrdf (the paper's route)")
      ->check(CLI::IsMember(names_of(kFiberBakeRoutes)));
  fiber
      .add_option_function<std::string>(
          "--estimator", [&r](const std::string& v) { r.estimator = v; },
          "how exits are tallied: plain (one by one) or nee (next-event estimation at "
          "every scattering, the table scaled to the walks' own exits; smooth boundary, "
          "direct route); default nee where it applies")
      ->check(CLI::IsMember(names_of(kFiberExitEstimators)));
  fiber.add_flag("--mirror-fold,!--no-mirror-fold", r.mirror_fold,
                 "average every cell with its images under the fiber's mirror symmetries "
                 "(default on; --no-mirror-fold turns it off)");
  fiber
      .add_option_function<int>(
          "--surface-samples", [&r](int v) { r.surface_samples = v; },
          "surface-lobe directions drawn per photon (smooth boundary; default " +
              std::to_string(FiberTableBakeOptions{}.surface_samples) + ")")
      ->check(CLI::Range(1, kMaxFiberSurfaceSamples));
  fiber
      .add_option_function<std::string>(
          "--entry", [&r](const std::string& v) { r.entry = v; },
          "how photons' entries are drawn: random or stratified (randomised Sobol' "
          "points per task; direct route); default stratified on the direct route")
      ->check(CLI::IsMember(names_of(kFiberEntrySamplings)));
  fiber
      .add_option("--surface-lobe", r.surface_lobe,
                  "the fiber's first-surface reflection: sampled (the photons' draws, binned) or "
                  "analytic (named in the table beside the cells, for readers that evaluate it "
                  "exactly: a smooth filament's lobe is narrower than the bins; smooth boundary, "
                  "direct route)")
      ->check(CLI::IsMember(names_of(kFiberSurfaceLobes)))
      ->capture_default_str();
  fiber.add_option("--colour", r.colour,
                   "the colour a cloth of the fiber should have as a d/8 instrument reads it "
                   "(srgb:#RRGGBB, lab:L,a,b, lab10:L,a,b, spectrum:FILE.csv, measured:NAME, "
                   "table:FILE.exr): the spec's dyes are scaled first to meet it, read through a "
                   "fiber-level ray trace of --colour-weave (docs/colour.md)");
  fiber.add_option("--colour-weave", r.colour_weave,
                   "woven sample options (.json) of the cloth that reads --colour (default: the "
                   "bundled poplin)");
  fiber.add_option("--seed", r.seed, "random seed");
  fiber
      .add_option("--passes", r.passes,
                  "passes over all bands (an interrupted bake keeps finished passes)")
      ->check(CLI::Range(uint64_t{1}, kMaxFiberBakePasses));
  fiber.add_option("--threads", r.threads, "threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxFiberBakeThreads));
}

// Sharding, checkpoints and what is printed.
void add_fiber_run_options(CLI::App& fiber, FiberBakeCliOptions& o) {
  fiber.add_option("--shard", o.request.shard,
                   "K/N: trace only shard K of N (bands) into a part file for `weft merge`");
  fiber.add_flag("--resume", o.request.resume,
                 "checkpoint every finished pass beside the output and continue from a "
                 "checkpoint an earlier run of this bake left there");
  fiber.add_flag("--json", o.json, "print the summary as JSON");
  fiber.add_flag("--quiet", o.quiet, "no progress bar");
}

}  // namespace

void add_bake_command(CLI::App& app, Commands& commands) {
  auto* bake = app.add_subcommand("bake", "Bake BSDF tables from physical specs");
  bake->require_subcommand(1);
  add_bake_fabric_command(*bake, commands);

  auto o = std::make_shared<FiberBakeCliOptions>();
  auto* fiber = bake->add_subcommand(
      "fiber", "Fiber BSDF table: Mie medium -> photon transport in the fiber -> table");
  fiber
      ->add_option("spec", o->request.spec,
                   "fiber spec JSON file, or a preset name (" + fiber_preset_list() + ")")
      ->required();
  fiber->add_option("-o,--output", o->request.output, "output table (.exr)")->required();
  add_fiber_sampling_options(*fiber, o->request);
  add_fiber_run_options(*fiber, *o);
  commands.push_back({fiber, [o](const RunLimits& l) { return run_bake_fiber(*o, l); }});
}

}  // namespace weft::cli
