// weft weave: a woven sample (one periodic repeat, yarn or fiber detail) as glTF; the older
// open-mesh patch when its options (--yarns, --yarn-radius-mm, ...) are given.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/scenes/weave_request.h"

namespace weft::cli {
namespace {

struct WeaveCliOptions {
  WeaveRequest request;
  bool json = false, quiet = false;
};

void print_legacy_weave(const WeaveCliOptions& o, const WeaveOutcome& r) {
  const std::string& output = o.request.output;
  if (o.json)
    std::cout << nlohmann::json({{"output", output},
                                 {"detail", "legacy open mesh"},
                                 {"triangles", r.legacy_triangles},
                                 {"vertices", r.legacy_vertices}})
                     .dump(2)
              << "\n";
  else
    std::printf("%s: %zu triangles, %zu vertices (legacy open-mesh patch)\n", output.c_str(),
                r.legacy_triangles, r.legacy_vertices);
}

void print_woven_sample(const WeaveCliOptions& o, const WeaveSummary& s) {
  const std::string& output = o.request.output;
  if (o.json) {
    std::cout << weave_summary_json(s, output);
    return;
  }
  std::printf("%s: %s detail, %s; period %.4f x %.4f mm (x by z), y in [%.4f, %.4f] mm; ",
              output.c_str(), s.detail.c_str(), s.source.c_str(), s.period_x_mm, s.period_z_mm,
              s.y_min_mm, s.y_max_mm);
  if (s.detail == "yarn")
    std::printf("%zu triangles\n", s.triangles);
  else
    std::printf("%zu curves, %zu segments; closest fibers %.2f um apart\n", s.curves,
                s.curve_segments, s.min_fiber_distance_um);
  if (s.nonwoven)
    std::printf(
        "  nonwoven: %d fibers (%d placements drawn), %.1f g/m^2, %.3f mm thick, "
        "solidity %.3f\n",
        s.nonwoven->fibers, s.nonwoven->attempts, s.nonwoven->areal_density_gsm,
        s.nonwoven->thickness_mm, s.nonwoven->solidity);
  if (o.quiet) return;
  for (const std::string& note : s.notes) std::printf("note: %s\n", note.c_str());
  if (!s.floating_warps.empty() || !s.floating_wefts.empty())
    std::printf("note: %zu warp and %zu weft threads never interlace (floating threads)\n",
                s.floating_warps.size(), s.floating_wefts.size());
}

int run_weave_command(const WeaveCliOptions& o, const RunLimits& limits) {
  WeaveRequest request = o.request;
  request.limits = limits;
  const WeaveOutcome r = run_weave(plan_weave(request));
  if (r.summary)
    print_woven_sample(o, *r.summary);
  else
    print_legacy_weave(o, r);
  return 0;
}

// The pattern and the yarns' sizes.
void add_weave_structure(CLI::App* sub, WeaveRequest& q) {
  WeaveOptions& w = q.options;
  sub->add_option("--pattern", w.pattern, "plain | twill:N/M | satin:N[/MOVE]");
  sub->add_option("--wif", w.wif, "WIF weaving draft (replaces --pattern)");
  sub->add_option("--detail", w.detail, "yarn (closed tubes) | fiber (round curves)");
  sub->add_option("--repeats", q.repeats, "copies of the repeat, N or NxM (x by z)");
  // Thread sizes come per direction: --warp-<size>-mm and --weft-<size>-mm.
  auto add_sizes = [&](const std::string& size, const std::string& what,
                       std::optional<double>& warp, std::optional<double>& weft) {
    sub->add_option("--warp-" + size + "-mm", warp, "warp " + what);
    sub->add_option("--weft-" + size + "-mm", weft, "weft " + what);
  };
  add_sizes("spacing", "centre-to-centre distance", w.warp_spacing_mm, w.weft_spacing_mm);
  sub->add_option("--yarn-width-mm", q.yarn_width_mm, "width of warp and weft yarns");
  sub->add_option("--yarn-thickness-mm", q.yarn_thickness_mm, "thickness of warp and weft yarns");
  add_sizes("width", "yarn width", w.warp_width_mm, w.weft_width_mm);
  add_sizes("thickness", "yarn thickness", w.warp_thickness_mm, w.weft_thickness_mm);
  sub->add_option("--warp-crimp-share", w.warp_crimp_share,
                  "share of the crimp height carried by the warp, [0, 1]; < 0: balanced");
  sub->add_option("--segments-per-crossing", w.segments_per_crossing,
                  "segments along a yarn per crossing");
}

// The fibers of a yarn.
void add_weave_fibers(CLI::App* sub, WeaveOptions& w) {
  sub->add_option("--fiber-radius-um", w.fiber_radius_um, "fiber radius, micrometres");
  sub->add_option("--fibers-per-yarn", w.fibers_per_yarn, "fibers in a yarn section");
  sub->add_option("--packing", w.packing, "fiber area / yarn section area (sets the count)");
  sub->add_option("--plies", w.plies, "plies per yarn");
  sub->add_option("--twist-per-mm", w.twist_per_mm, "fiber twist, turns per mm (Z > 0)");
  sub->add_option("--twist-angle-deg", w.twist_angle_deg,
                  "fiber twist as the outer fibers' helix angle, degrees");
  sub->add_option("--ply-twist-per-mm", w.ply_twist_per_mm, "ply twist, turns per mm (S < 0)");
}

// Nonwoven mats (--pattern nonwoven, docs/weave.md).
void add_weave_nonwoven(CLI::App* sub, WeaveOptions& w) {
  sub->add_option("--areal-density-gsm", w.areal_density_gsm, "nonwoven: mass per area, g/m^2");
  sub->add_option("--thickness-mm", w.thickness_mm, "nonwoven: mat thickness, mm");
  sub->add_option("--solidity", w.solidity,
                  "nonwoven: fiber volume / mat volume (instead of --thickness-mm)");
  sub->add_option("--inclination-sd-deg", w.inclination_sd_deg,
                  "nonwoven: standard deviation of the fibers' angle out of the plane, degrees");
  sub->add_option("--fiber-length-mm", w.fiber_length_mm,
                  "nonwoven: length of each straight fiber, at most half the tile");
  sub->add_option("--tile-mm", w.tile_mm, "nonwoven: side of the square periodic tile, mm");
  sub->add_option("--fiber-density-g-cm3", w.fiber_density_g_cm3,
                  "nonwoven: density of the fiber material, g/cm^3");
  sub->add_option("--seed", w.seed, "nonwoven: random seed (same seed, same fibers)");
}

// The legacy open-mesh patch, and --sides, which it shares with the sample's tubes.
void add_weave_legacy(CLI::App* sub, WeaveRequest& q) {
  sub->add_option("--sides", q.options.sides, "segments around each yarn tube");
  sub->add_option("--yarns", q.yarns, "legacy patch: yarns per direction");
  sub->add_option("--yarn-radius-mm", q.yarn_radius_mm, "legacy patch: circular yarn radius");
  sub->add_option("--spacing-mm", q.spacing_mm, "legacy patch: distance between parallel yarns");
  sub->add_option("--segments", q.segments, "legacy patch: segments along a yarn");
  sub->add_option("--amplitude-mm", q.amplitude_mm,
                  "legacy patch: centre-line amplitude (default: the radius)");
}

}  // namespace

void add_weave_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<WeaveCliOptions>();
  auto* sub = app.add_subcommand(
      "weave",
      "Generate a woven sample as glTF (metres, y up, warp along x, weft along z): one repeat of "
      "a pattern or WIF draft, periodic in x and z, as yarn tubes or fiber curves. Defaults: the "
      "bundled red-cotton poplin (scenes/examples/red-cotton-weave.json)");
  sub->add_option("--sample", o->request.sample,
                  "sample description JSON (keys: these options' names without the leading "
                  "dashes); options given here override it");
  add_weave_structure(sub, o->request);
  add_weave_fibers(sub, o->request.options);
  add_weave_nonwoven(sub, o->request.options);
  add_weave_legacy(sub, o->request);
  sub->add_option("-o,--output", o->request.output, "output (.gltf with embedded buffer, or .glb)")
      ->required();
  sub->add_flag("--json", o->json, "print a JSON summary");
  sub->add_flag("--quiet", o->quiet, "the summary only: no notes (errors are still printed)");
  commands.push_back({sub, [o](const RunLimits& l) { return run_weave_command(*o, l); }});
}

}  // namespace weft::cli
