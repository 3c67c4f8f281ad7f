// weft verify: computed fabric vs measurement vs the classic model, at every measured incidence,
// in one report folder (docs/verify.md). Binds options, makes the fiber physics' inputs (fiber
// bake, summation table) that the integrators library does not link, calls run_verify, plots.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "cli_util.h"
#include "commands.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/core/job_part.h"
#include "plot_util.h"
#include "weft/verify/fit_models.h"
#include "weft/core/error.h"
#include "weft/verify/verify.h"
#include "weft/materials/cook_torrance.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
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
  std::string fit_method = "lm";
  std::string classic_albedo;
  std::string shard;  // --shard K/N
  bool fit_params_given = false, fit_evaluations_given = false, fit_inner_given = false,
       fit_method_given = false;
  uint64_t seed = 1;
  int threads = 0;
  bool quiet = false, json = false;
};

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The run's CPU time, estimated before any work from its photons and particles (docs/verify.md
// "Time"): 'typical' at the rates measured on the bundled defaults, 'least' at the fastest rates
// measured anywhere (the fiber bake's kMinSecondsPerPhoton; 0.8 M particles/s on a sparse sample,
// docs/PERFORMANCE.md), which is what --yes-long is checked against.
struct VerifyEstimate {
  double typical = 0, least = 0;  // CPU seconds
  double photons = 0, particles = 0;
};
// Measured (docs/verify.md "Time"): red-cotton's full bake, 1.2 us per photon per core
// (docs/PERFORMANCE.md); the bundled poplin's fiber-level ray traces at default quality, computed
// and classic together, 316 s of CPU for 16.4 M particles and 6.6 M photons, so 18 us per
// particle; the plots and the rest, about 10 s of CPU whatever the quality.
constexpr double kTypicalSecondsPerPhoton = 1.2e-6;
constexpr double kTypicalSecondsPerParticle = 18e-6;
constexpr double kTypicalFixedSeconds = 10;
// The fiber-level renders (docs/verify.md "Renders"): 23 s of CPU at default quality for the four
// renders' 3.64 M camera samples on the bundled poplin, so 6.5 us per sample; counted here on a
// square film of weave_render_size (an upper bound: the film is whole repeats, one side shorter).
constexpr double kTypicalSecondsPerWeaveSample = 6.5e-6;
constexpr int kWeaveRenders = 4;  // computed and classic, reflection and transmission
constexpr double kLeastSecondsPerParticle = 1.25e-6;

VerifyEstimate estimate_verify(const VerifySettings& s, bool bake, bool fit, int fit_evaluations,
                               size_t fit_params) {
  VerifyEstimate e;
  const double bins = 2.0 * s.resolution * s.resolution;
  const double run_photons = bake ? double(s.fiber_photons_per_band) * kNumBands : 0.0;
  // Computed and classic, each 'particles_per_bin' per incident bin over all batches.
  const double run_particles = 2.0 * double(s.particles_per_bin) * bins;
  e.photons = run_photons;
  e.particles = run_particles;
  if (fit) {
    const FitInnerSettings inner = fit_inner_settings(s);
    const double inner_bins = 2.0 * inner.resolution * inner.resolution;
    // Per model: the search, the optimum again and the Jacobian (2 per parameter; the classic
    // model has 4).
    const double computed_evals = fit_evaluations + 1 + 2.0 * double(fit_params);
    const double classic_evals = fit_evaluations + 1 + 8.0;
    e.photons += computed_evals * double(inner.fiber_photons_per_band) * kNumBands + run_photons;
    e.particles += (computed_evals + classic_evals) * double(inner.particles_per_bin) * inner_bins +
                   run_particles;
  }
  const double weave_samples =
      double(kWeaveRenders) * s.weave_render_size * s.weave_render_size * s.weave_render_spp;
  e.typical = e.photons * kTypicalSecondsPerPhoton + e.particles * kTypicalSecondsPerParticle +
              weave_samples * kTypicalSecondsPerWeaveSample + kTypicalFixedSeconds;
  e.least = e.photons * kMinSecondsPerPhoton + e.particles * kLeastSecondsPerParticle;
  return e;
}

// A baked fiber table (--fiber TABLE): read and validated (read_exr names the file and the field at
// fault), and of kind "fiber".
TabulatedBsdfTable read_fiber_table(const std::string& file) {
  TabulatedBsdfTable t;
  try {
    t = TabulatedBsdfTable::read_exr(file);
  } catch (const Error& e) {
    throw Error("", "--fiber", std::string("not a usable fiber table: ") + e.what());
  }
  if (t.kind != "fiber")
    throw Error(file, "--fiber",
                "holds a " + t.kind + " table; verify needs a fiber table (weft bake fiber)");
  return t;
}

// "R,G,B", each a reflectance in [0, 1].
Rgb parse_classic_albedo(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    const auto x = finite_number(part);
    if (!x || *x < 0 || *x > 1)
      throw Error("", "--classic-albedo",
                  "'" + text + "' is not three reflectances R,G,B in [0, 1] (linear sRGB)");
    v.push_back(*x);
  }
  if (v.size() != 3)
    throw Error("", "--classic-albedo",
                "'" + text + "' is not three reflectances R,G,B in [0, 1] (linear sRGB)");
  return {v[0], v[1], v[2]};
}

// The classic baseline from a baked table (docs/verify.md "A baked fiber table"): roughness from
// the header; index from the spec the header names when a preset of that name has the header's
// spec hash, else cotton's; diffuse colour from --classic-albedo, else the table's total albedo
// minus the classic Cook-Torrance lobe's.
void classic_from_table(const std::string& file, const TabulatedBsdfTable& t,
                        const std::optional<Rgb>& albedo, const VerifySettings& s,
                        VerifyInputs& in) {
  const auto rough = fiber_table_roughness(t, file);
  if (!rough)
    throw Error(file, "roughness",
                "the table's header does not state the fiber's surface roughness (weft bake "
                "fiber writes it), which the classic baseline needs: bake the table with weft "
                "bake fiber, or give a fiber spec or preset");
  in.classic_distribution = *rough;
  in.classic_ior = kCottonIor;
  std::string ior_source = "cotton's index " + std::to_string(kCottonIor).substr(0, 5) +
                           " (the header names no preset with its spec hash)";
  const auto name = t.metadata.find("spec_name"), hash = t.metadata.find("spec_hash");
  if (name != t.metadata.end() && hash != t.metadata.end()) {
    const auto presets = fiber_preset_names();
    if (std::find(presets.begin(), presets.end(), name->second) != presets.end()) {
      const FiberSpec spec = parse_fiber_spec(fiber_preset_json(name->second), name->second);
      if (fiber_spec_hash_hex(spec) == hash->second) {
        in.classic_ior = spec.host_n[kNumBands / 2];  // 550 nm
        ior_source =
            "the index at 550 nm of preset " + name->second + " (the header's spec name and hash)";
      }
    }
  }
  if (albedo) {
    in.classic_diffuse = albedo;
    in.classic_source = "--classic-albedo; the table header's roughness; " + ior_source;
    return;
  }
  const std::vector<double> diffuse =
      classic_diffuse_from_fiber_table(t, *rough, in.classic_ior, s.seed, s.threads);
  Rgb rgb;
  if (t.channels == kNumBands) {
    for (int b = 0; b < kNumBands; ++b) in.volume_albedo[b] = diffuse[b];
    rgb = bands_to_linear_srgb([&](int b) { return diffuse[b]; });
  } else {
    rgb = Rgb(diffuse[0], diffuse[1], diffuse[2]);
  }
  for (int k = 0; k < 3; ++k) {
    const double v = k == 0 ? rgb.r : k == 1 ? rgb.g : rgb.b;
    if (!(v >= 0 && v <= 1))
      throw Error(file, "--classic-albedo",
                  "the classic baseline's diffuse colour from the table (its total albedo minus "
                  "the Cook-Torrance lobe's) is " +
                      std::to_string(v) + " in channel " + "RGB"[k] +
                      ", not a reflectance in [0, 1]: give --classic-albedo R,G,B");
  }
  if (t.channels != kNumBands) in.classic_diffuse = rgb;
  in.classic_source =
      "the fiber table: its total albedo minus the classic Cook-Torrance lobe's, per " +
      std::string(t.channels == kNumBands ? "band" : "channel") +
      "; the table header's roughness; " + ior_source;
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
  FitResult computed = fit_inner_model(
      "computed", spec_fit_parameters(spec, names),
      [&](const std::vector<double>& x) {
        return computed_inner_fiber_table(apply_spec_fit(spec, names, x), inner);
      },
      sample, inner, measured, options);
  computed.inner_model = computed_inner_model_name(inner);
  if (!o.quiet) std::fprintf(stderr, "weft: fitting the classic model\n");
  const MicrofacetModel model = base.classic_distribution.model;
  FitResult classic = fit_inner_model(
      "classic",
      classic_fit_parameters(report.classic_reflectance, base.classic_distribution.alpha),
      [&](const std::vector<double>& x) {
        return classic_inner_fiber_table(Rgb(x[0], x[1], x[2]), {model, x[3]}, base.classic_ior,
                                         inner);
      },
      sample, inner, measured, options);
  classic.inner_model = classic_inner_model_name(inner);

  // The fitted parameters at the run's quality.
  std::vector<double> values;
  for (const auto& p : computed.parameters) values.push_back(p.value);
  const FiberSpec fitted = apply_spec_fit(spec, names, values);
  VerifyInputs in;
  in.fiber_name = base.fiber_name + " (fitted)";
  in.sample_name = base.sample_name;
  const auto t0 = std::chrono::steady_clock::now();
  const FiberTableBakeOptions b =
      verify_bake_options(s.resolution, s.fiber_photons_per_band, s.seed, s.threads, false);
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
  FiberSpec spec;                                 // when --fiber is a spec or preset
  std::optional<TabulatedBsdfTable> fiber_table;  // when --fiber is a baked table (.exr)
  std::optional<Rgb> classic_albedo;              // --classic-albedo
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
  // --fiber names a spec or preset, or (.exr) a baked fiber table, whose resolution the run takes.
  if (std::filesystem::path(o.fiber).extension() == ".exr") {
    p.fiber_table = read_fiber_table(o.fiber);
    if (o.fit)
      throw Error(o.fiber, "--fit",
                  "the fit changes the fiber spec's parameters, and a baked table has no spec: "
                  "give a spec or preset");
    p.s.resolution = p.fiber_table->resolution;
  } else {
    p.spec = load_fiber_spec(o.fiber);
  }
  if (!o.classic_albedo.empty()) p.classic_albedo = parse_classic_albedo(o.classic_albedo);
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
    p.fit_options.method = parse_fit_method(o.fit_method);
    p.fit_options.max_evaluations = o.fit_evaluations;
    p.fit_options.validate(4);                       // the classic model always fits four
    (void)spec_fit_parameters(p.spec, p.fit_names);  // a spec without particles is refused here
  } else if (o.fit_params_given || o.fit_evaluations_given || o.fit_inner_given ||
             o.fit_method_given) {
    throw Error("",
                o.fit_params_given        ? "--fit-params"
                : o.fit_evaluations_given ? "--fit-evaluations"
                : o.fit_inner_given       ? "--fit-inner"
                                          : "--fit-method",
                "only with --fit");
  }
  return p;
}

// The time it will take, before it starts; above an hour (at the fastest rates) needs --yes-long.
void check_verify_time(const VerifyCliOptions& o, const VerifyPlan& p) {
  const unsigned cores =
      std::max(1u, p.s.threads > 0 ? unsigned(p.s.threads) : std::thread::hardware_concurrency());
  const VerifyEstimate e = estimate_verify(p.s, !p.fiber_table, o.fit,
                                           p.fit_options.max_evaluations, p.fit_names.size());
  if (!o.quiet)
    std::fprintf(stderr,
                 "weft verify: quality %s%s, %.3g M photons and %.3g M particles: about %s on "
                 "%u cores (%s of CPU; at least %s)\n",
                 o.quality.c_str(), o.fit ? " with --fit" : "", e.photons * 1e-6,
                 e.particles * 1e-6, format_seconds(e.typical / cores).c_str(), cores,
                 format_seconds(e.typical).c_str(), format_seconds(e.least / cores).c_str());
  check_long_work(e.least, 1.0, p.s.threads, "", "--quality",
                  "weft verify at quality " + o.quality + (o.fit ? " with --fit" : ""),
                  "0.5 us per photon and 1.25 us per particle per core at least");
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
             {"spec_hash", p.fiber_table ? p.fiber_table->checksum() : fiber_spec_hash_hex(p.spec)},
             {"program_version", WEFT_VERSION}};
  job.units_total = verify_traces(p.s).size() * DirectionGrid{p.s.resolution}.bins();
  job.shard = shard;
  job.extra = {{"threads", o.threads}};  // reported in metrics.json; results do not depend on it
  return job;
}

// The spectral fiber table through the bake cache (./.weft-cache, bake_cache.h): shards of a job
// that need it at once bake it once, and the merge reuses it. Returns false when interrupted.
bool fiber_from_cache(const VerifyPlan& p, VerifyInputs& in, const ProgressCallback& progress) {
  const FiberTableBakeOptions b =
      verify_bake_options(p.s.resolution, p.s.fiber_photons_per_band, p.s.seed, p.s.threads, false);
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
    if (!all) check_verify_time(o, p);  // a merge's ray traces are done
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
  if (p.fiber_table) {
    classic_from_table(o.fiber, *p.fiber_table, p.classic_albedo, s, in);
    in.fiber = *p.fiber_table;
    in.seconds["classic_from_table"] = since(t0);
  } else {
    if (!fiber_from_cache(p, in, progress)) {
      std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
      return 130;
    }
    in.seconds["fiber_bake"] = since(t0);
    in.classic_distribution = {p.spec.roughness_distribution, p.spec.roughness_alpha};
    in.classic_ior = p.spec.host_n[kNumBands / 2];  // 550 nm
    if (p.classic_albedo) {
      in.classic_diffuse = p.classic_albedo;
      in.classic_source = "--classic-albedo; the spec's roughness and index at 550 nm";
    }
  }
  if (job) return run_shard(o, p, sample, in, *job, progress);

  t0 = std::chrono::steady_clock::now();
  in.summation = sum_fabric_table(
      in.fiber, verify_summation_options(s.resolution, s.summation_samples, s.seed, s.threads),
      progress);
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
  sub->add_option("--fiber", o->fiber,
                  "fiber spec (.json) or preset, or a baked fiber table (.exr, weft bake fiber)")
      ->capture_default_str();
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
                  "objective evaluations per model's search, over all its restarts (the "
                  "uncertainty at the end adds 2 per parameter and 1)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_evaluations_given = true; });
  sub->add_option("--fit-inner", o->fit_inner,
                  "the model the fit evaluates: raytrace (the run's pipeline, few particles, "
                  "paths drawn from a proposal table re-centred between restarts) or summation "
                  "(the paper's summation table: cheaper, no light between fibers)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_inner_given = true; });
  sub->add_option("--fit-method", o->fit_method,
                  "the search: lm (Levenberg-Marquardt on the log residuals) or nelder-mead "
                  "(derivative-free, slower from a distant start)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->fit_method_given = true; });
  sub->add_option("--classic-albedo", o->classic_albedo,
                  "the classic baseline's diffuse colour R,G,B (linear sRGB reflectances); "
                  "default: the spec's volume albedo, or for a fiber table its total albedo "
                  "minus the Cook-Torrance lobe's");
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
