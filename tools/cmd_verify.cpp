// weft verify: computed fabric vs measurement vs the classic model, at every measured incidence,
// in one report folder (docs/verify.md). Binds options, makes the fiber physics' inputs (fiber
// bake, summation table) that the integrators library does not link, calls run_verify, plots.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.h"
#include "fabric_parts.h"
#include "job_part.h"
#include "plot_util.h"
#include "verify_fit.h"
#include "weft/core/error.h"
#include "weft/integrators/verify.h"
#include "weft/materials/fabric/bake_cache.h"
#include "weft/materials/fabric/fabric_summation.h"
#include "weft/materials/fabric/fiber_spec.h"
#include "weft/materials/fabric/fiber_table_bake.h"
#include "weft/scenes/weave.h"

namespace weft::cli {
namespace {

struct VerifyCliOptions {
  std::string measured, fiber = "red-cotton", weave, pattern, wif, quality = "default", output;
  bool fit = false;
  std::string fit_params =
      "dye_scale,particle_fraction_scale,particle_radius_scale,roughness_alpha";
  int fit_evaluations = 100;
  std::string fit_inner = "raytrace";
  std::string shard;  // --shard K/N
  bool fit_params_given = false, fit_evaluations_given = false, fit_inner_given = false;
  uint64_t seed = 1;
  int threads = 0;
  bool quiet = false, json = false;
};

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// --fit: both models fitted with the same objective and budget on their inner models, then the
// fitted parameters evaluated at the run's quality (run_verify again) as the "_fitted" models.
bool fit(const VerifyCliOptions& o, const FiberSpec& spec, const std::vector<std::string>& names,
         const FitOptions& options, const VerifySettings& s, const WovenSample& sample,
         const VerifyInputs& base, const MeasuredInplane& measured, VerifyReport& report,
         const ProgressCallback& progress) {
  FitInnerSettings inner = fit_inner_settings(s);
  inner.inner = parse_fit_inner(o.fit_inner);
  if (!o.quiet) std::fprintf(stderr, "\nweft: fitting the computed model (%s)\n", o.fiber.c_str());
  FitResult computed = fit_inplane(
      "computed", spec_fit_parameters(spec, names),
      [&](const std::vector<double>& x) {
        return computed_inner_curves(apply_spec_fit(spec, names, x), sample, inner, measured);
      },
      measured, options);
  computed.inner_model = computed_inner_model_name(inner);
  if (!o.quiet) std::fprintf(stderr, "weft: fitting the classic model\n");
  const MicrofacetModel model = base.classic_distribution.model;
  FitResult classic = fit_inplane(
      "classic",
      classic_fit_parameters(report.classic_reflectance, base.classic_distribution.alpha),
      [&](const std::vector<double>& x) {
        return classic_inner_curves(Rgb(x[0], x[1], x[2]), {model, x[3]}, base.classic_ior, sample,
                                    inner, measured);
      },
      measured, options);
  classic.inner_model = classic_inner_model_name(inner);

  // The fitted parameters at the run's quality.
  std::vector<double> values;
  for (const auto& p : computed.parameters) values.push_back(p.value);
  const FiberSpec fitted = apply_spec_fit(spec, names, values);
  VerifyInputs in;
  in.fiber_name = base.fiber_name + " (fitted)";
  in.sample_name = base.sample_name;
  const auto t0 = std::chrono::steady_clock::now();
  FiberTableBakeOptions b;
  b.resolution = s.resolution;
  b.photons_per_band = s.fiber_photons_per_band;
  b.seed = s.seed;
  b.threads = s.threads;
  b.spectral = true;
  FiberTableBakeResult fiber = bake_fiber_table(fitted, b, progress);
  if (fiber.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return false;
  }
  for (const auto& band : fiber.bands)
    in.volume_albedo[band.band] = band.exit_fraction - band.surface_fraction;
  in.fiber = std::move(fiber.table);
  in.classic_distribution = {model, classic.parameters[3].value};
  in.classic_ior = base.classic_ior;
  in.classic_diffuse =
      Rgb(classic.parameters[0].value, classic.parameters[1].value, classic.parameters[2].value);
  const VerifyReport again = run_verify(sample, in, measured, s, progress);
  if (again.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return false;
  }
  for (ModelCurves m : again.models) {
    m.key += "_fitted";
    m.label += ", fitted";
    report.models.push_back(std::move(m));
  }
  report.seconds["fit_computed"] = computed.seconds;
  report.seconds["fit_classic"] = classic.seconds;
  report.seconds["fit_at_run_quality"] = since(t0);
  report.fits = {std::move(computed), std::move(classic)};
  return true;
}

// The user's inputs, checked before any work (every way of running verify starts here).
struct VerifyPlan {
  VerifySettings s;
  std::filesystem::path measured_path;
  MeasuredInplane measured;
  FiberSpec spec;
  WeaveOptions weave;
  std::vector<std::string> fit_names;
  FitOptions fit_options;
};

VerifyPlan plan(const VerifyCliOptions& o) {
  VerifyPlan p;
  const VerifyQuality q = parse_verify_quality(o.quality);
  p.s = verify_settings(q);
  p.s.seed = o.seed;
  p.s.threads = o.threads;
  p.measured_path =
      o.measured.empty() ? bundled_measured_inplane() : std::filesystem::path(o.measured);
  p.measured = read_measured_inplane(p.measured_path);
  if (std::filesystem::path(o.fiber).extension() == ".exr")
    throw Error(o.fiber, "--fiber",
                "give a fiber spec or preset: the classic baseline's diffuse colour is the "
                "fiber's volume albedo, which a baked table does not record");
  p.spec = load_fiber_spec(o.fiber);
  if (!o.pattern.empty() && !o.wif.empty())
    throw Error("", "--wif", "give either --pattern or --wif, not both");
  WeaveOptions given;
  if (!o.pattern.empty()) given.pattern = o.pattern;
  if (!o.wif.empty()) given.wif = o.wif;
  given.detail = "fiber";  // the fiber-level reference
  const WeaveOptions base = o.weave.empty() ? WeaveOptions{} : read_weave_options(o.weave);
  p.weave = overlay(base, given);
  if (o.fit) {
    if (!o.shard.empty()) throw Error("", "--fit", "runs in one process, not with --shard");
    p.fit_names = parse_spec_fit_names(o.fit_params);
    (void)parse_fit_inner(o.fit_inner);
    p.fit_options.max_evaluations = o.fit_evaluations;
    p.fit_options.validate(4);                       // the classic model always fits four
    (void)spec_fit_parameters(p.spec, p.fit_names);  // a spec without particles is refused here
  } else if (o.fit_params_given || o.fit_evaluations_given) {
    throw Error("", o.fit_params_given ? "--fit-params" : "--fit-evaluations", "only with --fit");
  }
  return p;
}

// A sharded verify's job: the options that fix its result (a merge runs them again for the parts
// it does not hold), the content of its input files, and its units: the incident bins of every
// ray trace (verify_traces), trace after trace.
JobPart verify_job(const VerifyCliOptions& o, const VerifyPlan& p, Shard shard) {
  std::vector<std::filesystem::path> files{p.measured_path};
  std::error_code ec;
  for (const std::string& f : {o.weave, o.wif, o.fiber})
    if (!f.empty() && std::filesystem::is_regular_file(f, ec)) files.emplace_back(f);
  JobPart job;
  job.command = "verify";
  job.job = {{"options",
              {{"fiber", o.fiber},
               {"measured", o.measured},
               {"weave", o.weave},
               {"pattern", o.pattern},
               {"wif", o.wif},
               {"quality", o.quality},
               {"seed", o.seed}}},
             {"inputs", input_file_hashes(files)},
             {"spec_hash", fiber_spec_hash_hex(p.spec)},
             {"program_version", WEFT_VERSION}};
  job.units_total = verify_traces(p.s).size() * DirectionGrid{p.s.resolution}.bins();
  job.shard = shard;
  job.extra = {{"threads", o.threads}};  // reported in metrics.json; results do not depend on it
  return job;
}

// The spectral fiber table through the bake cache (./.weft-cache, bake_cache.h): shards of a job
// that need it at once bake it once, and the merge reuses it. Returns false when interrupted.
bool fiber_from_cache(const VerifyPlan& p, VerifyInputs& in, const ProgressCallback& progress) {
  FiberTableBakeOptions b;
  b.resolution = p.s.resolution;
  b.photons_per_band = p.s.fiber_photons_per_band;
  b.seed = p.s.seed;
  b.threads = p.s.threads;
  b.spectral = true;  // the colour table needs the spectrum
  std::filesystem::path file;
  try {
    file = cached_fiber_table(".weft-cache", p.spec, b, progress);
  } catch (const Error&) {
    if (interrupted()) return false;
    throw;
  }
  in.fiber = TabulatedBsdfTable::read_exr(file);
  in.volume_albedo = volume_albedo_of(in.fiber, file.string());
  return true;
}

// --shard K/N: the shard's units of the ray traces into a part file at o.output.
int run_shard(const VerifyCliOptions& o, const VerifyPlan& p, const WovenSample& sample,
              const VerifyInputs& in, const JobPart& job, const ProgressCallback& progress) {
  const uint64_t bins = DirectionGrid{p.s.resolution}.bins();
  const UnitRange range = shard_units(job.units_total, job.shard);
  const std::vector<VerifyTrace> traces = verify_traces(p.s);
  std::optional<ClassicFiber> classic;
  JobPart part = job;
  for (size_t t = 0; t < traces.size(); ++t) {
    const uint64_t first = std::max(range.first, t * bins),
                   last = std::min(range.last, (t + 1) * bins);
    if (first >= last) continue;
    if (traces[t].model == "classic" && !classic) classic = verify_classic_fiber(in, p.s, progress);
    FabricRaytraceOptions r = traces[t].options;
    r.first_bin = static_cast<int>(first - t * bins);
    r.bin_count = static_cast<int>(last - first);
    const FabricRaytraceResult res = raytrace_fabric_table(
        sample, traces[t].model == "classic" ? classic->table : in.fiber, r, progress);
    if (res.cancelled) {
      std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
      return 130;
    }
    for (uint64_t u = first; u < last; ++u) encode_fabric_bin(res, u - t * bins, part.units[u]);
  }
  write_job_part(o.output, part);
  std::printf("ray-trace units %llu..%llu of %llu (shard %u/%u) -> %s\n",
              static_cast<unsigned long long>(range.first),
              static_cast<unsigned long long>(range.last),
              static_cast<unsigned long long>(job.units_total), job.shard.index, job.shard.count,
              o.output.c_str());
  return 0;
}

// The whole run, or the merge of a sharded one ('all': every unit of its ray traces).
int run(const VerifyCliOptions& o, const JobPart* all = nullptr) {
  const auto t_all = std::chrono::steady_clock::now();
  const VerifyPlan p = plan(o);
  const VerifySettings& s = p.s;
  const MeasuredInplane& measured = p.measured;
  const Shard shard = o.shard.empty() ? Shard{} : parse_shard(o.shard, "--shard");
  std::optional<JobPart> job;
  if (!o.shard.empty()) {
    validate_output_paths({o.output}, {p.measured_path.string(), o.weave, o.wif, o.fiber});
    job = verify_job(o, p, shard);
  } else {
    check_verify_output(o.output);
  }
  if (all) {
    // The inputs must still be those the shards read.
    const JobPart now = verify_job(o, p, all->shard);
    if (const std::string why = job_difference(*all, now); !why.empty())
      throw Error("", "parts",
                  "the verify job's inputs changed since its shards ran (" + why + ")");
  }

  const auto progress = progress_bar(o.quiet);
  VerifyInputs in;
  in.fiber_name = o.fiber;
  auto t0 = std::chrono::steady_clock::now();
  const WovenSample sample = make_woven_sample(p.weave);
  in.sample_name = sample.summary.source + " (" + sample.summary.detail + ")";
  in.seconds["woven_sample"] = since(t0);

  t0 = std::chrono::steady_clock::now();
  if (!fiber_from_cache(p, in, progress)) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return 130;
  }
  in.seconds["fiber_bake"] = since(t0);
  in.classic_distribution = {p.spec.roughness_distribution, p.spec.roughness_alpha};
  in.classic_ior = p.spec.host_n[kNumBands / 2];  // 550 nm
  if (job) return run_shard(o, p, sample, in, *job, progress);

  t0 = std::chrono::steady_clock::now();
  FabricSummationOptions so;
  so.method = FabricSummation::kPaper;
  so.resolution = s.resolution;
  so.samples_per_cell = s.summation_samples;
  so.seed = s.seed;
  so.threads = s.threads;
  in.summation = sum_fabric_table(in.fiber, so, progress);
  in.seconds["summation"] = since(t0);

  VerifyTraced traced;
  if (all) {
    const uint64_t bins = DirectionGrid{s.resolution}.bins();
    const std::vector<VerifyTrace> traces = verify_traces(s);
    for (size_t t = 0; t < traces.size(); ++t) {
      const auto it = all->units.find(t * bins);
      if (it == all->units.end()) throw Error("", "parts", "a ray trace's first bin is missing");
      traced[{traces[t].model, traces[t].batch}] = assemble_fabric_bins(
          all->units, t * bins, bins, s.resolution, fabric_bin_channels(it->second, bins));
    }
  }
  VerifyReport report = run_verify(sample, in, measured, s, progress, all ? &traced : nullptr);
  if (report.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return 130;
  }
  if (o.fit &&
      !fit(o, p.spec, p.fit_names, p.fit_options, s, sample, in, measured, report, progress))
    return 130;
  report.seconds["total_before_report"] = since(t_all);
  write_verify_report(o.output, report, [&](const std::filesystem::path& staging) {
    const auto tp = std::chrono::steady_clock::now();
    run_plot_script(
        "plot_verify.py",
        {(staging / "inplane.csv").string(), (staging / "metrics.json").string(), staging.string()},
        o.output);
    report.seconds["plots"] = since(tp);
  });

  const auto find = [&](const std::string& key) -> const ModelCurves* {
    for (const auto& m : report.models)
      if (m.key == key) return &m;
    return nullptr;
  };
  if (o.json) {
    std::cout << verify_metrics_json(report);
  } else {
    std::printf("%s: %zu incidences, quality %s, %.1f s\n", o.output.c_str(),
                measured.curves.size(), o.quality.c_str(), since(t_all));
    std::printf("  %-36s %10s %10s %10s %10s\n", "RMS vs measured", "log norm", "rel norm",
                "log abs", "rel abs");
    for (const char* key : {"computed_raytrace", "computed_summation", "classic",
                            "computed_raytrace_fitted", "classic_fitted"})
      if (const ModelCurves* m = find(key))
        std::printf("  %-36s %10.3f %10.3f %10.3f %10.3f\n", m->label.c_str(),
                    m->normalized_overall.rms_log, m->normalized_overall.rms_rel,
                    m->absolute_overall.rms_log, m->absolute_overall.rms_rel);
    for (const auto& f : report.fits) {
      std::printf("  fit %s: inner rms_log %.3f -> %.3f, %d evaluations, %.1f s:", f.model.c_str(),
                  f.objective_start, f.objective, f.evaluations, f.seconds);
      for (const auto& fp : f.parameters)
        std::printf(" %s %.4g +- %.2g%s", fp.parameter.name.c_str(), fp.value, fp.sigma,
                    fp.at_bound ? " (at bound)" : "");
      std::printf("\n");
    }
  }
  return 0;
}

}  // namespace

void add_verify_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<VerifyCliOptions>();
  auto* sub = app.add_subcommand(
      "verify",
      "Computed fabric (fiber-level ray trace, paper's summation) and the classic Lambert + "
      "Cook-Torrance model\nagainst a measured in-plane table, at every measured incidence: "
      "curves, plots, metrics, colour table,\nin one report folder (inplane.csv, metrics.json, "
      "index.html, PNG and SVG plots)");
  sub->add_option("--measured", o->measured,
                  "measured in-plane table (format of materials/data/measured/*/inplane.csv; "
                  "default: the bundled MERL red fabric)");
  sub->add_option("--fiber", o->fiber, "fiber spec (.json) or preset")->capture_default_str();
  sub->add_option("--weave", o->weave, "woven sample options (.json; default: the bundled poplin)");
  sub->add_option("--pattern", o->pattern, "weave pattern: plain, twill:N/M, satin:N");
  sub->add_option("--wif", o->wif, "WIF weaving draft");
  sub->add_option("--quality", o->quality, "draft | default | publication")
      ->check(CLI::IsMember({"draft", "default", "publication"}))
      ->capture_default_str();
  sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
  sub->add_option("--threads", o->threads, "threads (0 = all cores; results do not depend on it)")
      ->check(CLI::Range(0, 4096));
  sub->add_option("-o,--output", o->output, "report folder (replaced whole)")->required();
  sub->add_flag("--fit", o->fit,
                "fit at most four fiber parameters (computed) and the classic model's diffuse "
                "colour and roughness to the measurement, then evaluate both at the run's quality");
  sub->add_option("--fit-params", o->fit_params,
                  "computed model's parameters, comma-separated: dye_scale, "
                  "particle_fraction_scale, particle_radius_scale, roughness_alpha")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_params_given = true; });
  sub->add_option("--fit-evaluations", o->fit_evaluations,
                  "objective evaluations per model's search (the uncertainty adds 2 per parameter)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_evaluations_given = true; });
  sub->add_option("--fit-inner", o->fit_inner,
                  "the model the fit evaluates: raytrace (the run's pipeline, few particles) or "
                  "summation (the paper's summation table: smooth, cheaper, no light between "
                  "fibers)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_inner_given = true; });
  sub->add_flag("--json", o->json, "print metrics.json on stdout");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  sub->add_option("--shard", o->shard,
                  "K/N: run only shard K of N of the ray traces (their incident bins) into a part "
                  "file -o PART; `weft merge` makes the report folder from all parts");
  commands.push_back({sub, [o] { return run(*o); }});
}

int merge_verify(const JobPart& all, const std::string& output, bool json) {
  VerifyCliOptions o;
  const auto& opt = all.job.at("options");
  o.fiber = opt.at("fiber").get<std::string>();
  o.measured = opt.at("measured").get<std::string>();
  o.weave = opt.at("weave").get<std::string>();
  o.pattern = opt.at("pattern").get<std::string>();
  o.wif = opt.at("wif").get<std::string>();
  o.quality = opt.at("quality").get<std::string>();
  o.seed = opt.at("seed").get<uint64_t>();
  o.threads = all.extra.value("threads", 0);
  o.output = output;
  o.json = json;
  o.quiet = true;
  return run(o, &all);
}

}  // namespace weft::cli
