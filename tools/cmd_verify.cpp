// weft verify: computed fabric vs measurement vs the classic model, at every measured incidence,
// in one report folder (docs/verify.md). Binds the request's options (verify/plan.h), checks the
// output and the time, runs the plan (verify/whole_run.h) with the progress bar and the plots,
// and prints.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_util.h"
#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/verify/plan.h"
#include "weft/verify/plot_scripts.h"
#include "weft/verify/report.h"
#include "weft/verify/suite.h"
#include "weft/verify/summary_text.h"
#include "weft/verify/whole_run.h"

namespace weft::cli {
namespace {

struct VerifyCliOptions {
  VerifyRequest request;
  bool quiet = false, json = false;
  bool suite = false;      // every fabric of a suite file
  std::string suite_file;  // empty: the bundled suite
  // Options given that a suite's fabrics set themselves.
  std::vector<std::string> per_fabric_given;
  RunLimits limits;  // the program's, under --quiet
};

// The time it will take, before it starts; above an hour (at the fastest rates) needs --yes-long.
void check_verify_time(const VerifyCliOptions& o, const VerifyPlan& p) {
  const VerifyRequest& r = p.request;
  if (!o.quiet) std::fputs(verify_estimate_text(p).c_str(), stderr);
  check_memory(o.limits, estimate_verify(p).scene_bytes, r.wif.empty() ? r.weave : r.wif,
               "--detail", "the ray-traced scene of the woven sample");
  check_long_work(o.limits, estimate_verify(p).least, 1.0, p.settings.threads, "", "--quality",
                  "weft verify at quality " + r.quality + (r.fit ? " with --fit" : ""),
                  kVerifyLeastRates);
}

// The hooks of a run: the progress bar, the notes unless --quiet, the plots.
VerifyHooks verify_hooks(const VerifyCliOptions& o, const VerifyPlan& p,
                         std::chrono::steady_clock::time_point t_all) {
  const VerifyRequest& r = p.request;
  VerifyHooks hooks;
  hooks.progress = progress_bar(o.limits, o.quiet);
  hooks.interrupted = interrupted;
  hooks.note = [quiet = o.quiet](const std::string& line) {
    if (!quiet) std::fputs(line.c_str(), stderr);
  };
  // Ended early on Ctrl-C (the report then stops after it: write_verify_report).
  hooks.draw = [output = r.output, threads = r.threads](const std::filesystem::path& staging) {
    plot_verify_figures(staging, output, threads, [] { return !interrupted(); });
  };
  hooks.started = t_all;
  return hooks;
}

// The whole run, a shard of it, or the merge of a sharded one ('all': every unit of its ray
// traces).
int run(const VerifyCliOptions& o, const JobPart* all = nullptr) {
  const auto t_all = std::chrono::steady_clock::now();
  const VerifyRequest& r = o.request;
  const VerifyPlan p = plan_verify(r);
  const std::vector<NamedPath> inputs = {{p.measured_path, "measured CSV"},
                                         {r.weave, "weave options"},
                                         {r.wif, "WIF draft"},
                                         {r.fiber, "fiber table or spec"},
                                         {p.weave.wif.value_or(""), "WIF draft"}};
  if (p.shard) {
    validate_output_paths(o.limits, {{r.output, "-o"}}, inputs);
  } else {
    validate_output_paths(o.limits, {}, inputs, {{r.output, "-o"}});
    check_verify_output(r.output);
    if (!all) check_verify_time(o, p);  // a merge's ray traces are done
  }
  const VerifyOutcome out = run_verify_plan(p, verify_hooks(o, p, t_all), all);
  if (out.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return 130;
  }
  if (out.part) {
    std::printf("ray-trace units %llu..%llu of %llu (shard %u/%u) -> %s\n",
                static_cast<unsigned long long>(out.part_units.first),
                static_cast<unsigned long long>(out.part_units.last),
                static_cast<unsigned long long>(out.part->units_total), out.part->shard.index,
                out.part->shard.count, r.output.c_str());
  } else if (o.json) {
    std::cout << verify_metrics_json(out.report);
  } else {
    std::fputs(verify_summary_text(p, out.report, seconds_since(t_all)).c_str(), stdout);
  }
  return 0;
}

// Every fabric of a suite: all planned (inputs read and checked) and the whole suite's time
// checked before any work; then one report each, then the suite's page.
int run_suite(const VerifyCliOptions& o) {
  const auto t_all = std::chrono::steady_clock::now();
  if (!o.per_fabric_given.empty())
    throw Error("", o.per_fabric_given.front(),
                "is set per fabric by the suite file; not with --suite");
  const VerifySuitePlan plan = plan_verify_suite(o.request, o.suite_file, o.limits);
  if (!o.quiet) std::fputs(verify_suite_estimate_text(plan).c_str(), stderr);
  check_verify_suite_time(plan, o.limits);
  VerifySuiteHooks hooks;
  hooks.fabric = [&](size_t k) {
    return verify_hooks(o, plan.plans[k], std::chrono::steady_clock::now());
  };
  hooks.starting = [&](size_t k) {
    if (!o.quiet)
      std::fprintf(stderr, "weft verify --suite: fabric %zu of %zu, %s\n", k + 1, plan.plans.size(),
                   plan.suite.fabrics[k].name.c_str());
  };
  hooks.failed = [&](size_t k, const std::string& error) {
    std::fprintf(stderr, "weft: %s: %s\n", plan.suite.fabrics[k].name.c_str(), error.c_str());
  };
  const VerifySuiteOutcome out = run_verify_suite(plan, hooks);
  if (out.cancelled) {
    std::fprintf(stderr,
                 "\nweft: verify --suite cancelled; the finished fabrics' reports stay, the "
                 "suite's page was not written\n");
    return 130;
  }
  const VerifyRequest& base = o.request;
  if (o.json)
    std::cout << verify_suite_json(plan.suite, out.rows);
  else
    std::printf("%s: %zu fabrics, quality %s, %.1f s\n%s", base.output.c_str(), out.rows.size(),
                base.quality.c_str(), seconds_since(t_all), verify_suite_text(out.rows).c_str());
  return out.failed ? 1 : 0;
}

}  // namespace

void add_verify_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<VerifyCliOptions>();
  VerifyRequest& r = o->request;
  auto* sub = app.add_subcommand(
      "verify",
      "Computed fabric (fiber-level ray trace, paper's summation) and the classic Lambert + "
      "Cook-Torrance model\nagainst a measured in-plane table, at every measured incidence: "
      "curves, plots, metrics, colour table,\nin one report folder (inplane.csv, metrics.json, "
      "index.html, PNG and SVG plots)");
  sub->add_option("--measured", r.measured,
                  "measured in-plane table (format of materials/data/measured/*/inplane.csv; "
                  "default: the bundled MERL red fabric)");
  sub->add_option("--colour-space", r.colour_space,
                  "the measured table's RGB space, over its '# colour_space:' line: srgb (linear "
                  "sRGB, as the models) or camera (absolute figures then not comparable)")
      ->check(CLI::IsMember({"srgb", "camera"}));
  sub->add_option("--fiber", r.fiber,
                  "fiber spec (.json) or preset, or a baked fiber table (.exr, weft bake fiber)")
      ->capture_default_str();
  sub->add_option("--weave", r.weave, "woven sample options (.json; default: the bundled poplin)");
  sub->add_option("--pattern", r.pattern, "weave pattern: plain, twill:N/M, satin:N");
  sub->add_option("--wif", r.wif, "WIF weaving draft");
  sub->add_option("--quality", r.quality, "draft | default | publication")
      ->check(CLI::IsMember({"draft", "default", "publication"}))
      ->capture_default_str();
  sub->add_option("--seed", r.seed, "random seed")->capture_default_str();
  sub->add_option("--threads", r.threads, "threads (0 = all cores; results do not depend on it)")
      ->check(CLI::Range(0, 4096));
  sub->add_option("-o,--output", r.output, "report folder (replaced whole)")->required();
  sub->add_flag("--fit", r.fit,
                "fit at most four fiber parameters (computed) and the classic model's diffuse "
                "colour and roughness to the measurement, then evaluate both at the run's quality");
  // The fit's options, each refused without --fit (plan_verify): whether it was given.
  const auto fit_option = [&](const std::string& name, auto& value, bool& given,
                              const std::string& help) {
    sub->add_option(name, value, help)
        ->capture_default_str()
        ->each([o, &given](const std::string&) { given = true; });
  };
  fit_option("--fit-params", r.fit_params, r.fit_params_given,
             "computed model's parameters, comma-separated: " + spec_fit_parameter_list(", "));
  fit_option("--fit-evaluations", r.fit_evaluations, r.fit_evaluations_given,
             "objective evaluations per model's search, over all its restarts (the uncertainty at "
             "the end adds 2 per parameter and 1)");
  fit_option("--fit-inner", r.fit_inner, r.fit_inner_given,
             "the model the fit evaluates: raytrace (the run's pipeline, few particles, paths "
             "drawn from a proposal table re-centred between restarts) or summation (the paper's "
             "summation table: cheaper, no light between fibers)");
  fit_option("--fit-seeds", r.fit_seeds, r.fit_seeds_given,
             "fit each model this many times (1 to " + std::to_string(kMaxFitSeeds) +
                 "), each at its own inner seed and from its own start, and keep the fit whose "
                 "optimum is best over all the seeds; metrics.json gives each parameter's spread "
                 "over the fits");
  fit_option("--fit-method", r.fit_method, r.fit_method_given,
             "the search: lm (Levenberg-Marquardt on the log residuals) or nelder-mead "
             "(derivative-free, slower from a distant start)");
  sub->add_option("--classic-albedo", r.classic_albedo,
                  "the classic baseline's diffuse colour R,G,B (linear sRGB reflectances); "
                  "default: the spec's volume albedo, or for a fiber table its total albedo "
                  "minus the Cook-Torrance lobe's");
  sub->add_option("--colour", r.colour,
                  "the cloth's colour as a d/8 instrument reads it (srgb:#RRGGBB, lab:L,a,b, "
                  "lab10:L,a,b, spectrum:FILE.csv, measured:NAME, table:FILE.exr): the spec's "
                  "dyes are scaled to meet it before the run (docs/colour.md)");
  sub->add_option("--colour-from", r.colour_from,
                  "measured: the colour is the measurement's own d/8 reading, and the computed "
                  "model's absolute figure is its calibrated one (computed_calibrated_rms_log)");
  sub->add_flag("--json", o->json, "print metrics.json on stdout");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  sub->add_option("--shard", r.shard,
                  "K/N: run only shard K of N of the ray traces (their incident bins) into a part "
                  "file -o PART; `weft merge` makes the report folder from all parts");
  sub->add_flag("--suite", o->suite,
                "every bundled measurement with its sample's description (verify/data/suite.json): "
                "a report per fabric in -o DIR and one page over them (index.html, suite.json)");
  sub->add_option("--suite-file", o->suite_file, "a suite file in place of the bundled one")
      ->each([o](const std::string&) { o->suite = true; });
  commands.push_back({sub, [o, sub](const RunLimits& program) {
                        o->limits = quieted(program, o->quiet);
                        // A suite file is a suite run, with or without --suite; an empty name
                        // would quietly be the bundled suite.
                        if (sub->count("--suite-file") > 0) {
                          if (o->suite_file.empty())
                            throw Error("", "--suite-file",
                                        "is empty: give a suite file, or --suite alone for the "
                                        "bundled suite");
                          o->suite = true;
                        }
                        if (!o->suite) return run(*o);
                        for (const char* name :
                             {"--measured", "--fiber", "--weave", "--pattern", "--wif", "--shard",
                              "--colour-space", "--fit", "--classic-albedo", "--colour"})
                          if (sub->count(name) > 0) o->per_fabric_given.push_back(name);
                        return run_suite(*o);
                      }});
}

int merge_verify(const JobPart& all, const std::string& output, bool json) {
  VerifyCliOptions o;
  o.request = verify_job_request(all, output);
  o.json = json;
  o.quiet = true;
  return run(o, &all);
}

}  // namespace weft::cli
