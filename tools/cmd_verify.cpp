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
  const VerifyRequest& r = o.request;
  const VerifyEstimate e = estimate_verify(p);
  if (!o.quiet)
    std::fprintf(stderr,
                 "weft verify: quality %s%s, %.3g M photons and %.3g M particles: about %s on "
                 "%u cores (%s of CPU; at least %s)\n",
                 r.quality.c_str(), r.fit ? " with --fit" : "", e.photons * 1e-6,
                 e.particles * 1e-6, format_seconds(e.typical / e.cores).c_str(), e.cores,
                 format_seconds(e.typical).c_str(), format_seconds(e.least / e.cores).c_str());
  check_long_work(o.limits, e.least, 1.0, p.settings.threads, "", "--quality",
                  "weft verify at quality " + r.quality + (r.fit ? " with --fit" : ""),
                  kVerifyLeastRates);
}

// "0.308 +- 0.005 [0.29..0.35]": a figure, its seed standard error, its range over the fits.
std::string figure_text(const FigureSamples& f) {
  char b[96];
  std::snprintf(b, sizeof b, "%.3f +- %.3f", f.value(), f.seed_se());
  std::string t = b;
  if (f.mean.size() > 1) {
    std::snprintf(b, sizeof b, " [%.2f..%.2f]", f.fit_min(), f.fit_max());
    t += b;
  }
  return t;
}

// The verdict, then the headline figures of each model with their uncertainty.
void print_verdict(const VerifyReport& report) {
  const std::vector<Verdict> verdicts = verify_verdicts(report);
  std::printf("  verdict:\n");
  for (int f = 0; f < 3; ++f) {
    const std::string note =
        f == kAbsoluteFigure ? not_comparable_note(report.measured.colour_space) : "";
    std::printf("   %s%s\n", figure_label(static_cast<FigureKind>(f)).c_str(),
                note.empty() ? "" : (" -- " + note).c_str());
    for (const Verdict& v : verdicts)
      if (v.figure == kFigureKeys[f]) std::printf("    - %s\n", v.text.c_str());
  }
  std::printf(
      "  %-36s %-28s %-28s %-28s\n", "RMS log (+- seed SE [over fits])", "shape",
      "paper's one-point",
      absolute_comparable(report.measured.colour_space) ? "absolute" : "absolute (not comparable)");
  for (const auto& m : report.models)
    if (!m.figures.fits.empty())
      std::printf("  %-36s %-28s %-28s %-28s\n", m.label.c_str(),
                  figure_text(m.figures.figure[kShapeFigure]).c_str(),
                  figure_text(m.figures.figure[kPaperFigure]).c_str(),
                  figure_text(m.figures.figure[kAbsoluteFigure]).c_str());
}

// The verdict and the figures, the metrics of each model against the measurement, and the fits.
void print_summary(const VerifyPlan& p, const VerifyReport& report, double seconds) {
  std::printf("%s: %zu incidences, quality %s, %.1f s\n", p.request.output.c_str(),
              p.measured.curves.size(), p.request.quality.c_str(), seconds);
  print_verdict(report);
  std::printf("  %-36s %10s %10s %10s %10s\n", "RMS vs measured", "log norm", "rel norm", "log abs",
              "rel abs");
  for (const std::string key : {"computed_raytrace", "computed_summation", "classic",
                                "computed_raytrace_fitted", "classic_fitted"}) {
    const auto m = std::find_if(report.models.begin(), report.models.end(),
                                [&](const ModelCurves& c) { return c.key == key; });
    if (m != report.models.end())
      std::printf("  %-36s %10.3f %10.3f %10.3f %10.3f\n", m->label.c_str(),
                  m->normalized_overall.rms_log, m->normalized_overall.rms_rel,
                  m->absolute_overall.rms_log, m->absolute_overall.rms_rel);
  }
  for (const auto& f : report.fits) {
    std::printf("  fit %s: inner rms_log %.3f -> %.3f, %d evaluations, %.1f s", f.model.c_str(),
                f.objective_start, f.objective, f.evaluations, f.seconds);
    if (f.seed_fits.size() > 1)
      std::printf(", kept seed %llu of %zu fits",
                  static_cast<unsigned long long>(f.seed_fits.front().seed), f.seed_fits.size());
    std::printf(":");
    for (const auto& fp : f.parameters) {
      std::printf(" %s %.4g +- %.2g%s", fp.parameter.name.c_str(), fp.value, fp.sigma,
                  fp.at_bound ? " (at bound)" : "");
      // The spread over the seeds' fits: what the measurement leaves undetermined shows here.
      if (std::isfinite(fp.sigma_seeds))
        std::printf(" [fits %.4g..%.4g]", fp.seeds_lo, fp.seeds_hi);
    }
    std::printf("\n");
  }
}

// The run of a checked plan, with the progress bar and the plots.
VerifyOutcome run_checked(const VerifyCliOptions& o, const VerifyPlan& p,
                          std::chrono::steady_clock::time_point t_all, const JobPart* all) {
  const VerifyRequest& r = p.request;
  VerifyHooks hooks;
  hooks.progress = progress_bar(o.limits, o.quiet);
  hooks.interrupted = interrupted;
  hooks.note = [&](const std::string& line) {
    if (!o.quiet) std::fputs(line.c_str(), stderr);
  };
  hooks.draw = [&](const std::filesystem::path& staging) {
    plot_verify_figures(staging, r.output, r.threads);
  };
  hooks.started = t_all;
  return run_verify_plan(p, hooks, all);
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
                                         {r.fiber, "fiber table or spec"}};
  if (p.shard) {
    validate_output_paths(o.limits, {{r.output, "-o"}}, inputs);
  } else {
    validate_output_paths(o.limits, {}, inputs, {{r.output, "-o"}});
    check_verify_output(r.output);
    if (!all) check_verify_time(o, p);  // a merge's ray traces are done
  }
  const VerifyOutcome out = run_checked(o, p, t_all, all);
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
    print_summary(p, out.report, seconds_since(t_all));
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
  const VerifyRequest& base = o.request;
  const VerifySuite suite = read_verify_suite(
      o.suite_file.empty() ? bundled_verify_suite() : std::filesystem::path(o.suite_file));
  std::vector<NamedPath> inputs = {{suite.file.string(), "suite file"}};
  for (const SuiteFabric& f : suite.fabrics) {
    inputs.push_back({f.measured, f.name + "'s measured CSV"});
    inputs.push_back({f.weave, f.name + "'s weave options"});
    inputs.push_back({f.wif, f.name + "'s WIF draft"});
    inputs.push_back({f.fiber, f.name + "'s fiber table or spec"});
  }
  validate_output_paths(o.limits, {}, inputs, {{base.output, "-o"}});
  check_suite_output(base.output);
  std::vector<VerifyPlan> plans;
  VerifyEstimate total;
  for (const SuiteFabric& f : suite.fabrics) {
    plans.push_back(plan_verify(suite_request(f, base, base.output)));
    const VerifyEstimate e = estimate_verify(plans.back());
    total.typical += e.typical;
    total.least += e.least;
    total.cores = e.cores;
  }
  if (!o.quiet)
    std::fprintf(stderr,
                 "weft verify --suite: %zu fabrics of %s, quality %s: about %s on %u cores\n",
                 plans.size(), suite.file.string().c_str(), base.quality.c_str(),
                 format_seconds(total.typical / total.cores).c_str(), total.cores);
  check_long_work(o.limits, total.least, 1.0, base.threads, "", "--quality",
                  "weft verify --suite at quality " + base.quality, kVerifyLeastRates);
  std::filesystem::create_directories(base.output);
  std::vector<SuiteRow> rows;
  bool failed = false;
  for (size_t k = 0; k < plans.size(); ++k) {
    SuiteRow row{suite.fabrics[k], nullptr, ""};
    if (!o.quiet)
      std::fprintf(stderr, "weft verify --suite: fabric %zu of %zu, %s\n", k + 1, plans.size(),
                   row.fabric.name.c_str());
    try {
      const VerifyOutcome out = run_checked(o, plans[k], std::chrono::steady_clock::now(), nullptr);
      if (out.cancelled) {
        std::fprintf(stderr,
                     "\nweft: verify --suite cancelled; the finished fabrics' reports "
                     "stay, the suite's page was not written\n");
        return 130;
      }
      row.metrics = nlohmann::json::parse(verify_metrics_json(out.report));
    } catch (const Error& e) {
      row.error = e.what();
      failed = true;
      std::fprintf(stderr, "weft: %s: %s\n", row.fabric.name.c_str(), e.what());
    }
    rows.push_back(std::move(row));
  }
  write_text_atomically(std::filesystem::path(base.output) / "suite.json",
                        verify_suite_json(suite, rows));
  write_text_atomically(std::filesystem::path(base.output) / "index.html",
                        verify_suite_html(suite, rows));
  if (o.json)
    std::cout << verify_suite_json(suite, rows);
  else
    std::printf("%s: %zu fabrics, quality %s, %.1f s\n%s", base.output.c_str(), rows.size(),
                base.quality.c_str(), seconds_since(t_all), verify_suite_text(rows).c_str());
  return failed ? 1 : 0;
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
                        if (!o->suite) return run(*o);
                        for (const char* name : {"--measured", "--fiber", "--weave", "--pattern",
                                                 "--wif", "--shard", "--fit", "--classic-albedo"})
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
