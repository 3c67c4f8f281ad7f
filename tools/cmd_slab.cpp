// weft slab: MCML-style reflectance and transmittance of a plane-parallel slab (Henyey-Greenstein
// scattering, Fresnel boundaries) for validating the photon transport engine. Binds the request
// (fiber/transport_slab.h), runs its plan and prints.
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.h"
#include "weft/fiber/transport_slab.h"

namespace weft::cli {
namespace {

struct SlabCliOptions {
  SlabRequest request;
  bool json = false, quiet = false;
};

int run_slab_command(const SlabCliOptions& o, const RunLimits& limits) {
  const SlabPlan plan = plan_slab(o.request);
  const SlabOutcome out = run_slab(plan, progress_bar(limits, o.quiet));
  const SlabResult& r = out.result;
  if (o.json) {
    std::cout << out.summary.dump(2) << "\n";
  } else {
    std::printf("%-9s %12s %12s\n", "quantity", "value", "std_error");
    for (const auto& [key, e] : slab_quantities(r))
      std::printf("%-9s %12.6f %12.6f\n", key, e.mean, e.std_error);
    std::printf("photons %llu of %llu, scatterings %llu%s\n",
                static_cast<unsigned long long>(r.photons),
                static_cast<unsigned long long>(plan.batch.items),
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
  auto cli = std::make_shared<SlabCliOptions>();
  SlabRequest* o = &cli->request;
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
  sub->add_flag("--json", cli->json, "print JSON");
  sub->add_flag("--quiet", cli->quiet, "no progress bar");
  commands.push_back({sub, [cli](const RunLimits& l) { return run_slab_command(*cli, l); }});
}

}  // namespace weft::cli
