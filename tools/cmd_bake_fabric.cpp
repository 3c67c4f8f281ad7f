// weft bake fabric: a fiber table (file, or a spec baked on demand) and a woven sample -> a fabric
// BSDF table, by the paper's summation, our visible-section summation or the ray-traced reference.
// The request, its plan and its run are the fabric library's (fabric/fabric_bake.h); this file
// binds the options and prints.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/materials/weave_table.h"

namespace weft::cli {
namespace {

struct BakeFabricCliOptions {
  FabricBakeRequest request;
  bool json = false, quiet = false;
};

void print_weave_summary(const nlohmann::json& w) {
  std::printf("%s: weave table, %s positions, resolution %d; relative noise %.4g\n",
              w.at("file").get<std::string>().c_str(), w.at("positions").get<std::string>().c_str(),
              w.at("resolution").get<int>(), w.at("relative_noise").get<double>());
}

// The line without --json of what 1 % noise per channel would cost (noise_cost_summary).
void print_noise_cost(const nlohmann::json& cost, const nlohmann::json& noise) {
  std::printf("relative noise per channel");
  for (const auto& n : noise) std::printf(" %.3g %%", 100 * n.get<double>());
  std::printf("; 1 %% in each would take");
  for (const auto& c : cost.at("cpu_seconds_to_target")) {
    if (c.is_null())
      std::printf(" -");
    else
      std::printf(" %.3g", c.get<double>());
  }
  std::printf(" CPU-s\n");
}

// The summary without --json: light arriving along the normal, where it goes; and what a view
// along the normal gathers under uniform light (the renderer's reading). They differ for a
// non-reciprocal table: the paper's sum transmits nothing downwards but light from below upwards
// (fabric_summation.h).
void print_bake_summary(const FabricBakeRequest& o, const nlohmann::json& j) {
  auto mean = [&](const char* key) {
    double s = 0;
    for (const auto& x : j.at(key)) s += x.get<double>();
    return s / static_cast<double>(j.at(key).size());
  };
  std::printf(
      "%s: %s, R = %d, %.2f s; light along the normal: reflected %.4f, transmitted %.4f; seen "
      "along the normal: reflected %.4f, transmitted %.4f (means over channels)\n",
      o.output.c_str(), o.method.c_str(), o.resolution, j.at("seconds").get<double>(),
      mean("reflectance_normal_incidence"), mean("transmittance_normal_incidence"),
      mean("reflectance_normal_view"), mean("transmittance_normal_view"));
  if (j.contains("noise_cost")) print_noise_cost(j["noise_cost"], j["relative_noise_per_channel"]);
  if (j.contains("weave")) print_weave_summary(j["weave"]);
}

int run(const BakeFabricCliOptions& cli, const RunLimits& program) {
  FabricBakeRequest o = cli.request;
  o.limits = quieted(program, cli.quiet);
  const FabricBakePlan plan = plan_fabric_bake(o);
  if (!plan.note.empty()) std::fprintf(stderr, "weft: %s\n", plan.note.c_str());
  const FabricBakeHooks hooks{progress_bar(o.limits, cli.quiet), [](const std::string& w) {
                                std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
                              }};
  const FabricBakeResult r = run_fabric_bake(plan, hooks);
  if (r.cancelled) {
    std::fprintf(stderr, "\nweft: bake cancelled; %s\n",
                 o.resume ? "--resume continues from the last checkpoint" : "nothing was written");
    return 130;
  }
  if (r.part_units)
    std::printf("incident bins %llu..%llu (shard %u/%u) -> %s\n",
                static_cast<unsigned long long>(r.part_units->first),
                static_cast<unsigned long long>(r.part_units->last), r.shard.index, r.shard.count,
                o.output.c_str());
  for (const std::string& note : r.notes) std::fprintf(stderr, "weft: %s\n", note.c_str());
  if (r.part_units) return 0;
  if (cli.json)
    std::cout << r.summary.dump(2) << "\n";
  else
    print_bake_summary(o, r.summary);
  return 0;
}

// The ray tracer's options.
void add_raytrace_options(CLI::App* sub, FabricBakeRequest& o) {
  sub->add_option(
         "--estimator", o.estimator,
         "raytrace: hero (one channel steers each path, MIS over channels, roulette on the "
         "largest weight, splitting; the default) | nee (hero, and the exits estimated at every "
         "scattering by next-event draws) | mean (the channels' mean steers; no splitting)")
      ->check(CLI::IsMember(names_of(kFabricEstimators)));
  sub->add_option("--next-event-rays", o.next_event_rays,
                  "raytrace, nee: draws of the exit per scattering (default " +
                      std::to_string(kDefaultNextEventRays) + ")")
      ->check(CLI::Range(1, kMaxNextEventRays));
  sub->add_option("--launch-lattice", o.launch_lattice,
                  "raytrace, nee: particles per launch block, their entry points on a lattice "
                  "over the repeat (default " +
                      std::to_string(kDefaultLaunchLattice) + ")")
      ->check(CLI::Range(1, kMaxLaunchLattice));
  sub->add_option("--straight-through", o.straight_through,
                  "raytrace: exact (the light passing between the fibers computed, the particles "
                  "book what meets a fiber; the default) | sampled (booked by the particles too)")
      ->check(CLI::IsMember(names_of(kStraightThroughNames)));
  sub->add_option("--sheen-resolution", o.sheen_resolution,
                  "raytrace, fiber detail, a fiber table with an analytic surface lobe: the "
                  "fibers' first-surface reflection booked apart over half vectors on a grid of "
                  "this resolution (e.g. 64: 2.2 degree bins), so that the table keeps a mirror "
                  "peak narrower than its bins; off unless given");
  sub->add_option("--sheen-window", o.sheen_window,
                  "raytrace, with --sheen-resolution: bins per side of the half vectors' window "
                  "about the normal (default " +
                      std::to_string(FabricRaytraceOptions{}.sheen_window) + ")");
  sub->add_option("--sheen-light-resolution", o.sheen_light_resolution,
                  "raytrace, with --sheen-resolution: the sheen's light bins, 2 or 4 times -R "
                  "(nested in the table's; each table bin's particles launched from them in "
                  "turn), so that a peak that moves with the light is not blurred across a light "
                  "bin; default: the table's");
  sub->add_option("--sheen-light", o.sheen_light,
                  "raytrace, with --sheen-resolution: first-surface (the first fiber's surface "
                  "reflection; the default) | reflected (every reflected exit whose half vector "
                  "lies in the window: a finer grid about the mirror)");
  sub->add_option("--split-threshold", o.split_threshold,
                  "raytrace, hero: split a particle whose largest channel weight exceeds this "
                  "(default " +
                      std::to_string(FabricRaytraceOptions{}.split_threshold) + ")");
  sub->add_option("--max-scatterings", o.max_scatterings,
                  "raytrace: a particle ends at its Nth scattering, its weight booked as lost, so "
                  "the table holds the paths of fewer (what each order of scattering carries; "
                  "default " +
                      std::to_string(FabricRaytraceOptions{}.max_scatterings) + ")")
      ->check(CLI::Range(1, 1000000));
  sub->add_option("--weave-out", o.weave_out,
                  "raytrace: also the weave table (.exr): how the cloth varies over its repeat, "
                  "the exits binned by where they cross the cloth's mid-plane (with --shard, the "
                  "parts carry it and `weft merge --weave-out` writes it)");
  sub->add_option("--weave-positions", o.weave_positions,
                  "raytrace, --weave-out: position cells over the repeat, N (N x N) or UxV (u "
                  "along the warp), each 1 to " +
                      std::to_string(WeaveTable::kMaxPositions) + " (default " +
                      std::to_string(kDefaultWeavePositions) + ")");
  sub->add_option("--weave-resolution", o.weave_resolution,
                  "raytrace, --weave-out: the weave table's coarse bins per hemisphere side, 1 to "
                  "the table's -R (default " +
                      std::to_string(kDefaultWeaveResolution) + ", at most -R)");
}

}  // namespace

void add_bake_fabric_command(CLI::App& bake, Commands& commands) {
  auto cli = std::make_shared<BakeFabricCliOptions>();
  FabricBakeRequest& o = cli->request;
  auto* sub =
      bake.add_subcommand("fabric",
                          "Fabric BSDF table from a fiber table and a woven sample (summation, "
                          "summation-visible or the ray-traced reference)");
  sub->add_option("--fiber", o.fiber,
                  "fiber table (.exr), or a fiber spec or preset to bake (with --thread-colours: "
                  "the fiber the colours dye)")
      ->capture_default_str();
  sub->add_option("--warp-fiber", o.warp_fiber,
                  "raytrace: the warp yarns' fiber (table, spec or preset; default --fiber)");
  sub->add_option("--weft-fiber", o.weft_fiber,
                  "raytrace: the weft yarns' fiber (table, spec or preset; default --fiber)");
  sub->add_option("--colour", o.colour,
                  "the cloth's colour as a d/8 instrument reads it: srgb:#RRGGBB, lab:L,a,b, "
                  "lab10:L,a,b or spectrum:FILE.csv; --fiber's dyes are scaled to meet it "
                  "(docs/colour.md)");
  sub->add_flag("--thread-colours", o.thread_colours,
                "raytrace: one fiber per thread colour of the WIF draft, --fiber dyed to the "
                "colour (docs/fabric-bsdf.md; at most " +
                    std::to_string(kMaxThreadColours) + " colours)");
  sub->add_option_function<std::string>(
         "--thread-colour-method", [&o](const std::string& v) { o.thread_colour_method = v; },
         "how --thread-colours dyes --fiber: match (each colour's absorbers solved so that a cloth "
         "of that thread alone reads the colour; default) or rule (the colour's smooth uplift, no "
         "readings: darker and more saturated than the swatch)")
      ->check(CLI::IsMember(names_of(kThreadColourMethods)));
  sub->add_option("--method", o.method, "summation | summation-visible | raytrace")
      ->check(CLI::IsMember(names_of(kFabricMethods)))
      ->capture_default_str();
  sub->add_option("--weave", o.weave, "woven sample options (.json; default: the bundled poplin)");
  sub->add_option("--pattern", o.pattern, "weave pattern: plain, twill:N/M, satin:N");
  sub->add_option("--wif", o.wif, "WIF weaving draft");
  sub->add_option("--detail", o.detail,
                  "sample detail for the ray tracer: yarn or fiber (default: the --weave file's, "
                  "else yarn)")
      ->check(CLI::IsMember({"yarn", "fiber"}));
  sub->add_option("-R,--resolution", o.resolution, "fabric table bins per hemisphere side")
      ->check(CLI::Range(1, TabulatedBsdfTable::kMaxResolution))
      ->capture_default_str();
  sub->add_option("--samples", o.samples,
                  "summations: direction pairs per cell pair (1 to " +
                      std::to_string(kMaxSummationSamples) +
                      "); raytrace: particles per incident bin (1 to 2^36)")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 36));
  add_raytrace_options(sub, o);
  sub->add_option("--seed", o.seed, "random seed")->capture_default_str();
  sub->add_option("--threads", o.threads, "threads (0 = all cores)")->check(CLI::Range(0, 4096));
  sub->add_option("-o,--output", o.output, "output fabric table (.exr)")->required();
  sub->add_option("--shard", o.shard,
                  "raytrace: K/N, trace only shard K of N (incident bins) into a part file for "
                  "`weft merge`");
  sub->add_flag("--resume", o.resume,
                "raytrace: checkpoint finished incident bins beside the output and continue "
                "from a checkpoint an earlier run left there");
  sub->add_flag("--json", cli->json, "print a JSON summary");
  sub->add_flag("--quiet", cli->quiet, "no progress bar");
  commands.push_back({sub, [cli](const RunLimits& l) { return run(*cli, l); }});
}

int merge_fabric_bake(const JobPart& all, const std::string& output, const std::string& weave_out,
                      bool json) {
  const nlohmann::json j = merge_fabric_parts(all, output, weave_out);
  if (j.contains("weave") && !json) print_weave_summary(j["weave"]);
  if (json)
    std::cout << j.dump(2) << "\n";
  else
    std::printf("%s: ray-traced fabric table, R = %d, merged; relative noise %.4g\n",
                output.c_str(), j.at("resolution").get<int>(),
                j.at("relative_noise").get<double>());
  return 0;
}

}  // namespace weft::cli
