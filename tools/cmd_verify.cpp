// weft verify: computed fabric vs measurement vs the classic model, at every measured incidence,
// in one report folder (docs/verify.md). Binds options, makes the fiber physics' inputs (fiber
// bake, summation table) that the integrators library does not link, calls run_verify, plots.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "plot_util.h"
#include "weft/core/error.h"
#include "weft/integrators/verify.h"
#include "weft/materials/fabric/fabric_summation.h"
#include "weft/materials/fabric/fiber_spec.h"
#include "weft/materials/fabric/fiber_table_bake.h"
#include "weft/scenes/weave.h"

namespace weft::cli {
namespace {

struct VerifyCliOptions {
  std::string measured, fiber = "red-cotton", weave, pattern, wif, quality = "default", output;
  uint64_t seed = 1;
  int threads = 0;
  bool quiet = false, json = false;
};

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(const VerifyCliOptions& o) {
  const auto t_all = std::chrono::steady_clock::now();
  // Everything the user gave is checked before any work.
  const VerifyQuality q = parse_verify_quality(o.quality);
  VerifySettings s = verify_settings(q);
  s.seed = o.seed;
  s.threads = o.threads;
  const std::filesystem::path measured_path =
      o.measured.empty() ? bundled_measured_inplane() : std::filesystem::path(o.measured);
  const MeasuredInplane measured = read_measured_inplane(measured_path);
  if (std::filesystem::path(o.fiber).extension() == ".exr")
    throw Error(o.fiber, "--fiber",
                "give a fiber spec or preset: the classic baseline's diffuse colour is the "
                "fiber's volume albedo, which a baked table does not record");
  const FiberSpec spec = load_fiber_spec(o.fiber);
  if (!o.pattern.empty() && !o.wif.empty())
    throw Error("", "--wif", "give either --pattern or --wif, not both");
  WeaveOptions given;
  if (!o.pattern.empty()) given.pattern = o.pattern;
  if (!o.wif.empty()) given.wif = o.wif;
  given.detail = "fiber";  // the fiber-level reference
  const WeaveOptions base = o.weave.empty() ? WeaveOptions{} : read_weave_options(o.weave);
  check_verify_output(o.output);

  const auto progress = progress_bar(o.quiet);
  VerifyInputs in;
  in.fiber_name = o.fiber;
  auto t0 = std::chrono::steady_clock::now();
  const WovenSample sample = make_woven_sample(overlay(base, given));
  in.sample_name = sample.summary.source + " (" + sample.summary.detail + ")";
  in.seconds["woven_sample"] = since(t0);

  t0 = std::chrono::steady_clock::now();
  FiberTableBakeOptions b;
  b.resolution = s.resolution;
  b.photons_per_band = s.fiber_photons_per_band;
  b.seed = s.seed;
  b.threads = s.threads;
  b.spectral = true;  // the colour table needs the spectrum
  FiberTableBakeResult fiber = bake_fiber_table(spec, b, progress);
  if (fiber.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return 130;
  }
  in.seconds["fiber_bake"] = since(t0);
  for (const auto& band : fiber.bands)
    in.volume_albedo[band.band] = band.exit_fraction - band.surface_fraction;
  in.classic_distribution = {spec.roughness_distribution, spec.roughness_alpha};
  in.classic_ior = spec.host_n[kNumBands / 2];  // 550 nm
  in.fiber = std::move(fiber.table);

  t0 = std::chrono::steady_clock::now();
  FabricSummationOptions so;
  so.method = FabricSummation::kPaper;
  so.resolution = s.resolution;
  so.samples_per_cell = s.summation_samples;
  so.seed = s.seed;
  so.threads = s.threads;
  in.summation = sum_fabric_table(in.fiber, so, progress);
  in.seconds["summation"] = since(t0);

  VerifyReport report = run_verify(sample, in, measured, s, progress);
  if (report.cancelled) {
    std::fprintf(stderr, "\nweft: verify cancelled; nothing was written\n");
    return 130;
  }
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
    for (const char* key : {"computed_raytrace", "computed_summation", "classic"})
      if (const ModelCurves* m = find(key))
        std::printf("  %-36s %10.3f %10.3f %10.3f %10.3f\n", m->label.c_str(),
                    m->normalized_overall.rms_log, m->normalized_overall.rms_rel,
                    m->absolute_overall.rms_log, m->absolute_overall.rms_rel);
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
  sub->add_flag("--json", o->json, "print metrics.json on stdout");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  commands.push_back({sub, [o] { return run(*o); }});
}

}  // namespace weft::cli
