// weft bench sheen: how much of a cloth's mirror peak fabric tables keep, against the brute-force
// reference (bench/sheen_bench.h; docs/fabric-bsdf.md, "Sharp sheen: what a table keeps").
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "weft/bench/sheen_bench.h"
#include "weft/core/atomic_file.h"
#include "weft/core/params.h"

namespace weft::cli {
namespace {

struct SheenOptions {
  SheenRequest request;
  std::string incidences = "30,45,60", azimuths = "0,90", reference_out;
  std::string reference_light = name_of(kSheenReferenceNames, SheenRequest{}.reference);
  bool json = false;
};

nlohmann::json peak_json(const InplanePeak& p) {
  return {{"beta", p.beta},
          {"view_deg", p.view_deg},
          {"base", p.base},
          {"fwhm_deg", p.fwhm_deg},
          {"mirror_beta", p.mirror_beta}};
}

// Batch b's file of --reference-out OUT.exr: OUT-<b + 1>.exr.
std::filesystem::path batch_path(const std::filesystem::path& out, int b) {
  return out.parent_path() /
         (out.stem().string() + "-" + std::to_string(b + 1) + out.extension().string());
}

void print(const SheenRequest& r, const SheenResult& res, bool json) {
  if (json) {
    nlohmann::json cases = nlohmann::json::array();
    for (const SheenCase& c : res.cases) {
      nlohmann::json tables = nlohmann::json::array();
      for (size_t k = 0; k < c.tables.size(); ++k)
        tables.push_back({{"file", r.tables[k]},
                          {"peak", peak_json(c.tables[k])},
                          {"peak_ratio", c.tables[k].beta / c.reference.beta},
                          {"mirror_ratio", c.tables[k].mirror_beta / c.reference.mirror_beta}});
      cases.push_back({{"incidence_deg", c.incidence_deg},
                       {"azimuth_deg", c.azimuth_deg},
                       {"reference", peak_json(c.reference)},
                       {"reference_beta_se", c.reference_beta_se},
                       {"reference_mirror_se", c.reference_mirror_se},
                       {"tables", tables}});
      if (!c.reference_curve.beta.empty())
        cases.back()["reference_curve"] = {{"view_deg", c.reference_curve.view_deg},
                                           {"beta", c.reference_curve.beta},
                                           {"beta_se", c.reference_curve.beta_se}};
    }
    std::cout << nlohmann::json{{"cases", cases}, {"cpu_seconds", res.cpu_seconds}}.dump(2) << "\n";
    return;
  }
  if (r.reference == SheenReference::narrow)
    std::printf(
        "reference: a narrow light (cone %g deg), exits in a %g deg band in bins of %g deg, read"
        " after a %g deg running mean; %llu particles per case x %d batches, %d next-event draws"
        "%s, %.0f CPU s\n",
        r.narrow.half_angle_deg, r.narrow.band_deg, r.narrow.bin_deg, r.smooth_deg,
        static_cast<unsigned long long>(r.narrow_particles), r.batches, r.narrow_next_event_rays,
        r.narrow_reference.empty() ? "" : (" (read from " + r.narrow_reference + ")").c_str(),
        res.cpu_seconds);
  else
    std::printf("reference: R %d, %llu particles per bin x %d batches, %.0f CPU s\n", r.resolution,
                static_cast<unsigned long long>(r.particles_per_bin), r.batches, res.cpu_seconds);
  for (const SheenCase& c : res.cases) {
    std::printf(
        "incidence %2.0f, azimuth %3.0f: reference peak %.3f +- %.3f at %.1f deg, FWHM %.1f"
        " deg (base %.3f); at the mirror %.3f +- %.3f\n",
        c.incidence_deg, c.azimuth_deg, c.reference.beta, c.reference_beta_se, c.reference.view_deg,
        c.reference.fwhm_deg, c.reference.base, c.reference.mirror_beta, c.reference_mirror_se);
    for (size_t k = 0; k < c.tables.size(); ++k)
      std::printf(
          "  %s: peak %.3f (%.2f of the reference) at %.1f deg, FWHM %.1f deg; at the mirror %.3f"
          " (%.2f)\n",
          r.tables[k].c_str(), c.tables[k].beta, c.tables[k].beta / c.reference.beta,
          c.tables[k].view_deg, c.tables[k].fwhm_deg, c.tables[k].mirror_beta,
          c.tables[k].mirror_beta / c.reference.mirror_beta);
  }
}

// Plans, checks the outputs, measures, writes the reference when asked, and prints.
int run(const SheenOptions& o, const RunLimits& limits) {
  SheenRequest req = o.request;
  req.incidences_deg = parse_range(o.incidences, "--incidence", 64);
  req.azimuths_deg = parse_range(o.azimuths, "--azimuth", 64);
  req.reference = value_of(kSheenReferenceNames, o.reference_light, "", "--reference-light");
  const SheenPlan plan = plan_sheen(req);
  const bool narrow = req.reference == SheenReference::narrow, out = !o.reference_out.empty();
  if (narrow && out)
    check_output_paths({{o.reference_out, "--reference-out"}},
                       {{req.fiber, "--fiber"}, {req.narrow_reference, "--narrow-reference"}});
  for (int b = 0; b < plan.request.batches && !narrow && out; ++b)
    TabulatedBsdfTable::check_output_path(batch_path(o.reference_out, b), "--reference-out");
  const SheenResult res = run_sheen(plan, progress_bar(limits, false));
  if (res.cancelled) return 130;
  if (narrow && out) write_narrow_reference(o.reference_out, plan, res);
  for (size_t b = 0; b < res.batches.size() && out; ++b)
    res.batches[b].write_exr(batch_path(o.reference_out, static_cast<int>(b)));
  print(plan.request, res, o.json);
  return 0;
}

}  // namespace

void add_bench_sheen_command(CLI::App& bench, Commands& commands) {
  auto o = std::make_shared<SheenOptions>();
  SheenRequest& r = o->request;
  auto* cmd = bench.add_subcommand(
      "sheen", "How much of a cloth's mirror peak fabric tables keep, against a fine reference");
  cmd->add_option("--fiber", r.fiber, "fiber table (.exr) the reference traces")->required();
  cmd->add_option("--weave", r.weave, "woven sample options (.json)")->capture_default_str();
  cmd->add_option("--table", r.tables, "fabric table(s) (.exr) to measure against the reference");
  cmd->add_option("--reference-light", o->reference_light,
                  "the reference: grid (the ray trace's cells at -R, the light bins' beams) | "
                  "narrow (a narrow light per case, its exits binned in its plane)")
      ->check(CLI::IsMember(names_of(kSheenReferenceNames)))
      ->capture_default_str();
  cmd->add_option("-R,--resolution", r.resolution, "grid: the reference's grid")
      ->capture_default_str();
  cmd->add_option("--particles", r.particles_per_bin, "particles per light bin and batch")
      ->capture_default_str();
  cmd->add_option("--narrow-particles", r.narrow_particles, "narrow: particles per case and batch")
      ->capture_default_str();
  cmd->add_option("--nee", r.narrow_next_event_rays,
                  "narrow: next-event draws per scattering (0: the exits alone)")
      ->capture_default_str();
  cmd->add_option("--cone", r.narrow.half_angle_deg,
                  "narrow: the light's half angle, degrees (0: collimated)")
      ->capture_default_str();
  cmd->add_option("--band", r.narrow.band_deg, "narrow: the exits' band across the plane, degrees")
      ->capture_default_str();
  cmd->add_option("--bin", r.narrow.bin_deg, "narrow: the exits' bins along the plane, degrees")
      ->capture_default_str();
  cmd->add_option("--smooth", r.smooth_deg, "narrow: running mean the peak is read after, degrees")
      ->capture_default_str();
  cmd->add_option("--batches", r.batches, "independent traces (the peak's standard error)")
      ->capture_default_str();
  cmd->add_option("--incidence", o->incidences, "light zeniths, degrees (a,b,c), each in [10, 85]")
      ->capture_default_str();
  cmd->add_option("--azimuth", o->azimuths, "planes of incidence, degrees (0: the warp's)")
      ->capture_default_str();
  cmd->add_option("--reference-out", o->reference_out,
                  "write the reference's batches: grid, OUT.exr names OUT-1.exr, OUT-2.exr, ...; "
                  "narrow, one JSON file of every case's batch curves");
  cmd->add_option("--narrow-reference", r.narrow_reference,
                  "narrow: an earlier run's --reference-out (JSON), read, not traced");
  cmd->add_option("--reference", r.reference_batches,
                  "an earlier run's reference batches (.exr, two or more), read, not traced");
  cmd->add_option("--seed", r.seed, "seed of the first batch")->capture_default_str();
  cmd->add_option("--threads", r.threads, "threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--json", o->json, "print JSON");
  commands.push_back({cmd, [o](const RunLimits& limits) { return run(*o, limits); }});
}

}  // namespace weft::cli
