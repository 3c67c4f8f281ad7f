// weft weave: a woven sample (one periodic repeat, yarn or fiber detail) as glTF; the older
// open-mesh patch when its options (--yarns, --yarn-radius-mm, ...) are given.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/scenes/weave.h"

namespace weft::cli {
namespace {

// Parses "N" or "NxM" into repeats along x and z.
void parse_repeats(const std::string& text, int& nx, int& nz) {
  const auto x = text.find_first_of("xX");
  try {
    size_t used = 0;
    if (x == std::string::npos) {
      nx = nz = std::stoi(text, &used);
      if (used != text.size()) throw std::invalid_argument(text);
    } else {
      nx = std::stoi(text.substr(0, x), &used);
      if (used != x) throw std::invalid_argument(text);
      nz = std::stoi(text.substr(x + 1), &used);
      if (used != text.size() - x - 1) throw std::invalid_argument(text);
    }
  } catch (const std::exception&) {
    throw Error("", "repeats", "expected N or NxM, got '" + text + "'");
  }
}

// The open-mesh patch of earlier versions; its options cannot be mixed with the sample's.
int run_legacy(const CLI::App& sub, WeaveParams p, const WeaveOptions& w, bool sides_given,
               const std::string& output, bool json, const RunLimits& limits) {
  for (const char* name : {"--sample", "--wif", "--detail", "--repeats", "--warp-spacing-mm",
                           "--weft-spacing-mm", "--yarn-width-mm", "--yarn-thickness-mm",
                           "--fibers-per-yarn", "--packing", "--segments-per-crossing"})
    if (sub.get_option(name)->count())
      throw Error("", std::string(name).substr(2),
                  "cannot be combined with the legacy open-mesh options (--yarns, "
                  "--yarn-radius-mm, --spacing-mm, --segments, --amplitude-mm)");
  validate_output_paths(limits, {{output, "--output"}}, {});
  p.pattern = w.pattern.value_or("plain");
  if (sides_given) p.sides = *w.sides;
  const auto meshes = make_weave(p);
  size_t tris = 0, verts = 0;
  for (const auto& m : meshes) tris += m.triangle_count(), verts += m.vertex_count();
  write_weave(output, p);
  if (json)
    std::cout << nlohmann::json({{"output", output},
                                 {"detail", "legacy open mesh"},
                                 {"triangles", tris},
                                 {"vertices", verts}})
                     .dump(2)
              << "\n";
  else
    std::printf("%s: %zu triangles, %zu vertices (legacy open-mesh patch)\n", output.c_str(), tris,
                verts);
  return 0;
}

}  // namespace

void add_weave_command(CLI::App& app, Commands& commands) {
  struct Options {
    WeaveOptions w;  // what the command line gives
    std::string sample, repeats, output;
    std::optional<double> yarn_width_mm, yarn_thickness_mm;
    WeaveParams legacy;
    bool json = false, quiet = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "weave",
      "Generate a woven sample as glTF (metres, y up, warp along x, weft along z): one repeat of "
      "a pattern or WIF draft, periodic in x and z, as yarn tubes or fiber curves. Defaults: the "
      "bundled red-cotton poplin (scenes/examples/red-cotton-weave.json)");
  sub->add_option("--sample", o->sample,
                  "sample description JSON (keys: these options' names without the leading "
                  "dashes); options given here override it");
  sub->add_option("--pattern", o->w.pattern, "plain | twill:N/M | satin:N[/MOVE]");
  sub->add_option("--wif", o->w.wif, "WIF weaving draft (replaces --pattern)");
  sub->add_option("--detail", o->w.detail, "yarn (closed tubes) | fiber (round curves)");
  sub->add_option("--repeats", o->repeats, "copies of the repeat, N or NxM (x by z)");
  // Thread sizes come per direction: --warp-<size>-mm and --weft-<size>-mm.
  auto add_sizes = [&](const std::string& size, const std::string& what,
                       std::optional<double>& warp, std::optional<double>& weft) {
    sub->add_option("--warp-" + size + "-mm", warp, "warp " + what);
    sub->add_option("--weft-" + size + "-mm", weft, "weft " + what);
  };
  add_sizes("spacing", "centre-to-centre distance", o->w.warp_spacing_mm, o->w.weft_spacing_mm);
  sub->add_option("--yarn-width-mm", o->yarn_width_mm, "width of warp and weft yarns");
  sub->add_option("--yarn-thickness-mm", o->yarn_thickness_mm, "thickness of warp and weft yarns");
  add_sizes("width", "yarn width", o->w.warp_width_mm, o->w.weft_width_mm);
  add_sizes("thickness", "yarn thickness", o->w.warp_thickness_mm, o->w.weft_thickness_mm);
  sub->add_option("--warp-crimp-share", o->w.warp_crimp_share,
                  "share of the crimp height carried by the warp, [0, 1]; < 0: balanced");
  sub->add_option("--segments-per-crossing", o->w.segments_per_crossing,
                  "segments along a yarn per crossing");
  sub->add_option("--fiber-radius-um", o->w.fiber_radius_um, "fiber radius, micrometres");
  sub->add_option("--fibers-per-yarn", o->w.fibers_per_yarn, "fibers in a yarn section");
  sub->add_option("--packing", o->w.packing, "fiber area / yarn section area (sets the count)");
  sub->add_option("--plies", o->w.plies, "plies per yarn");
  sub->add_option("--twist-per-mm", o->w.twist_per_mm, "fiber twist, turns per mm (Z > 0)");
  sub->add_option("--twist-angle-deg", o->w.twist_angle_deg,
                  "fiber twist as the outer fibers' helix angle, degrees");
  sub->add_option("--ply-twist-per-mm", o->w.ply_twist_per_mm, "ply twist, turns per mm (S < 0)");
  // Nonwoven mats (--pattern nonwoven, docs/weave.md).
  sub->add_option("--areal-density-gsm", o->w.areal_density_gsm, "nonwoven: mass per area, g/m^2");
  sub->add_option("--thickness-mm", o->w.thickness_mm, "nonwoven: mat thickness, mm");
  sub->add_option("--solidity", o->w.solidity,
                  "nonwoven: fiber volume / mat volume (instead of --thickness-mm)");
  sub->add_option("--inclination-sd-deg", o->w.inclination_sd_deg,
                  "nonwoven: standard deviation of the fibers' angle out of the plane, degrees");
  sub->add_option("--fiber-length-mm", o->w.fiber_length_mm,
                  "nonwoven: length of each straight fiber, at most half the tile");
  sub->add_option("--tile-mm", o->w.tile_mm, "nonwoven: side of the square periodic tile, mm");
  sub->add_option("--fiber-density-g-cm3", o->w.fiber_density_g_cm3,
                  "nonwoven: density of the fiber material, g/cm^3");
  sub->add_option("--seed", o->w.seed, "nonwoven: random seed (same seed, same fibers)");
  // Shared with the legacy patch: segments around each yarn tube.
  auto* sides = sub->add_option("--sides", o->w.sides, "segments around each yarn tube");
  // The legacy open-mesh patch.
  auto* yarns = sub->add_option("--yarns", o->legacy.yarns, "legacy patch: yarns per direction");
  auto* radius = sub->add_option("--yarn-radius-mm", o->legacy.yarn_radius_mm,
                                 "legacy patch: circular yarn radius");
  auto* spacing = sub->add_option("--spacing-mm", o->legacy.spacing_mm,
                                  "legacy patch: distance between parallel yarns");
  auto* segments =
      sub->add_option("--segments", o->legacy.segments, "legacy patch: segments along a yarn");
  auto* amplitude = sub->add_option("--amplitude-mm", o->legacy.amplitude_mm,
                                    "legacy patch: centre-line amplitude (default: the radius)");
  sub->add_option("-o,--output", o->output, "output (.gltf with embedded buffer, or .glb)")
      ->required();
  sub->add_flag("--json", o->json, "print a JSON summary");
  sub->add_flag("--quiet", o->quiet, "the summary only: no notes (errors are still printed)");
  commands.push_back(
      {sub, [o, sub, sides, yarns, radius, spacing, segments, amplitude](const RunLimits& limits) {
         if (yarns->count() || radius->count() || spacing->count() || segments->count() ||
             amplitude->count())
           return run_legacy(*sub, o->legacy, o->w, sides->count() > 0, o->output, o->json, limits);
         // Unset options come from --sample, else from the bundled sample (or a WIF draft's sizes).
         WeaveOptions given = o->w;
         if (!o->repeats.empty()) {
           int nx = 1, nz = 1;
           parse_repeats(o->repeats, nx, nz);
           given.repeats_x = nx, given.repeats_z = nz;
         }
         // --yarn-<size>-mm sets both directions' size, instead of either of its own options.
         auto both = [](const std::optional<double>& yarn, const std::string& size,
                        std::optional<double>& warp, std::optional<double>& weft) {
           if (!yarn) return;
           if (warp || weft)
             throw Error("", "yarn-" + size + "-mm",
                         "give it or --warp-" + size + "-mm/--weft-" + size + "-mm, not both");
           warp = weft = yarn;
         };
         both(o->yarn_width_mm, "width", given.warp_width_mm, given.weft_width_mm);
         both(o->yarn_thickness_mm, "thickness", given.warp_thickness_mm, given.weft_thickness_mm);
         auto one_of = [](bool a, bool b, const char* field, const char* what) {
           if (a && b) throw Error("", field, std::string("give either ") + what + ", not both");
         };
         one_of(given.pattern.has_value(), given.wif.has_value(), "wif", "--pattern or --wif");
         one_of(given.packing.has_value(), given.fibers_per_yarn.has_value(), "packing",
                "--packing or --fibers-per-yarn");
         one_of(given.twist_per_mm.has_value(), given.twist_angle_deg.has_value(),
                "twist-angle-deg", "--twist-per-mm or --twist-angle-deg");
         one_of(given.thickness_mm.has_value(), given.solidity.has_value(), "solidity",
                "--thickness-mm or --solidity");
         const WeaveOptions base =
             o->sample.empty() ? WeaveOptions{} : read_weave_options(o->sample);
         const WeaveOptions options = overlay(base, given);
         validate_output_paths(
             limits, {{o->output, "--output"}},
             {{o->sample, "sample description"}, {options.wif.value_or(""), "WIF draft"}});
         const WovenSample sample = make_woven_sample(options);
         write_woven(o->output, sample);
         const WeaveSummary& s = sample.summary;
         if (o->json) {
           std::cout << weave_summary_json(s, o->output);
           return 0;
         }
         std::printf("%s: %s detail, %s; period %.4f x %.4f mm (x by z), y in [%.4f, %.4f] mm; ",
                     o->output.c_str(), s.detail.c_str(), s.source.c_str(), s.period_x_mm,
                     s.period_z_mm, s.y_min_mm, s.y_max_mm);
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
         if (o->quiet) return 0;
         for (const std::string& note : s.notes) std::printf("note: %s\n", note.c_str());
         if (!s.floating_warps.empty() || !s.floating_wefts.empty())
           std::printf("note: %zu warp and %zu weft threads never interlace (floating threads)\n",
                       s.floating_warps.size(), s.floating_wefts.size());
         return 0;
       }});
}

}  // namespace weft::cli
