// weft weave: a woven sample (one periodic repeat, yarn or fiber detail) as glTF; the older
// open-mesh patch when its options (--yarns, --yarn-radius-mm, ...) are given.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
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

}  // namespace

void add_weave_command(CLI::App& app, Commands& commands) {
  struct Options {
    WeaveOptions w;
    std::string sample, repeats, output;
    std::optional<double> yarn_width_mm, yarn_thickness_mm;
    WeaveParams legacy;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "weave",
      "Generate a woven sample as glTF (metres, y up, warp along x, weft along z): one repeat of "
      "a pattern or WIF draft, periodic in x and z, as yarn tubes or fiber curves. Defaults: the "
      "bundled red-cotton poplin (scenes/examples/red-cotton-weave.json)");
  sub->add_option("--sample", o->sample,
                  "sample description JSON (keys as these options without dashes' leading --); "
                  "options given here override it");
  sub->add_option("--pattern", o->w.pattern, "plain | twill:N/M | satin:N[/MOVE]");
  sub->add_option("--wif", o->w.wif, "WIF weaving draft (replaces --pattern)");
  sub->add_option("--detail", o->w.detail, "yarn (closed tubes) | fiber (round curves)");
  sub->add_option("--repeats", o->repeats, "copies of the repeat, N or NxM (x by z)");
  sub->add_option("--warp-spacing-mm", o->w.warp_spacing_mm, "warp centre-to-centre distance");
  sub->add_option("--weft-spacing-mm", o->w.weft_spacing_mm, "weft centre-to-centre distance");
  sub->add_option("--yarn-width-mm", o->yarn_width_mm, "width of warp and weft yarns");
  sub->add_option("--yarn-thickness-mm", o->yarn_thickness_mm, "thickness of warp and weft yarns");
  sub->add_option("--warp-width-mm", o->w.warp_width_mm, "warp yarn width");
  sub->add_option("--weft-width-mm", o->w.weft_width_mm, "weft yarn width");
  sub->add_option("--warp-thickness-mm", o->w.warp_thickness_mm, "warp yarn thickness");
  sub->add_option("--weft-thickness-mm", o->w.weft_thickness_mm, "weft yarn thickness");
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
  commands.push_back(
      {sub, [o, sub, sides, yarns, radius, spacing, segments, amplitude] {
         const bool legacy = yarns->count() || radius->count() || spacing->count() ||
                             segments->count() || amplitude->count();
         if (legacy) {
           for (const char* name :
                {"--sample", "--wif", "--detail", "--repeats", "--warp-spacing-mm",
                 "--weft-spacing-mm", "--yarn-width-mm", "--yarn-thickness-mm", "--fibers-per-yarn",
                 "--packing", "--segments-per-crossing"})
             if (sub->get_option(name)->count())
               throw Error("", std::string(name).substr(2),
                           "cannot be combined with the legacy open-mesh options (--yarns, "
                           "--yarn-radius-mm, --spacing-mm, --segments, --amplitude-mm)");
           o->legacy.pattern = o->w.pattern;
           if (sides->count()) o->legacy.sides = o->w.sides;
           const auto meshes = make_weave(o->legacy);
           size_t tris = 0, verts = 0;
           for (const auto& m : meshes) tris += m.triangle_count(), verts += m.vertex_count();
           write_weave(o->output, o->legacy);
           if (o->json)
             std::cout << nlohmann::json({{"output", o->output},
                                          {"detail", "legacy open mesh"},
                                          {"triangles", tris},
                                          {"vertices", verts}})
                              .dump(2)
                       << "\n";
           else
             std::printf("%s: %zu triangles, %zu vertices (legacy open-mesh patch)\n",
                         o->output.c_str(), tris, verts);
           return 0;
         }
         // Defaults: the bundled sample; then a --sample file; then the options given here.
         WeaveOptions w = red_cotton_weave_options();
         if (!o->sample.empty()) {
           std::ifstream in(o->sample);
           if (!in) throw Error(o->sample, "", "cannot open");
           nlohmann::json j;
           try {
             j = nlohmann::json::parse(in);
           } catch (const nlohmann::json::exception& e) {
             throw Error(o->sample, "", std::string("invalid JSON: ") + e.what());
           }
           ParamReader r(j, o->sample, "");
           const WeaveOptions s =
               read_weave_options(r, std::filesystem::path(o->sample).parent_path());
           w = red_cotton_weave_options();
           // A sample file sets what it names; the rest stays as bundled.
           auto take = [](auto& dst, const auto& src) {
             if (src) dst = src;
           };
           w.pattern = s.pattern, w.wif = s.wif, w.detail = s.detail;
           w.repeats_x = s.repeats_x, w.repeats_z = s.repeats_z;
           w.segments_per_crossing = s.segments_per_crossing, w.sides = s.sides;
           take(w.warp_spacing_mm, s.warp_spacing_mm), take(w.weft_spacing_mm, s.weft_spacing_mm);
           take(w.warp_width_mm, s.warp_width_mm), take(w.weft_width_mm, s.weft_width_mm);
           take(w.warp_thickness_mm, s.warp_thickness_mm);
           take(w.weft_thickness_mm, s.weft_thickness_mm);
           take(w.warp_crimp_share, s.warp_crimp_share), take(w.fiber_radius_um, s.fiber_radius_um);
           take(w.fibers_per_yarn, s.fibers_per_yarn), take(w.packing, s.packing);
           take(w.plies, s.plies), take(w.twist_per_mm, s.twist_per_mm);
           take(w.twist_angle_deg, s.twist_angle_deg), take(w.ply_twist_per_mm, s.ply_twist_per_mm);
           if (s.fibers_per_yarn) w.packing.reset();
           if (s.twist_angle_deg) w.twist_per_mm.reset();
         }
         auto given = [&](const char* name) { return sub->get_option(name)->count() > 0; };
         if (given("--pattern")) w.pattern = o->w.pattern, w.wif.clear();
         if (given("--wif")) w.wif = o->w.wif;
         if (given("--pattern") && given("--wif"))
           throw Error("", "wif", "give either --pattern or --wif, not both");
         if (given("--detail")) w.detail = o->w.detail;
         if (!o->repeats.empty()) parse_repeats(o->repeats, w.repeats_x, w.repeats_z);
         if (given("--segments-per-crossing")) w.segments_per_crossing = o->w.segments_per_crossing;
         if (given("--sides")) w.sides = o->w.sides;
         if (o->yarn_width_mm && (o->w.warp_width_mm || o->w.weft_width_mm))
           throw Error("", "yarn-width-mm", "give it or --warp-width-mm/--weft-width-mm, not both");
         if (o->yarn_thickness_mm && (o->w.warp_thickness_mm || o->w.weft_thickness_mm))
           throw Error("", "yarn-thickness-mm",
                       "give it or --warp-thickness-mm/--weft-thickness-mm, not both");
         auto set = [](std::optional<double>& dst, const std::optional<double>& src) {
           if (src) dst = src;
         };
         set(w.warp_width_mm, o->yarn_width_mm), set(w.weft_width_mm, o->yarn_width_mm);
         set(w.warp_thickness_mm, o->yarn_thickness_mm),
             set(w.weft_thickness_mm, o->yarn_thickness_mm);
         set(w.warp_spacing_mm, o->w.warp_spacing_mm), set(w.weft_spacing_mm, o->w.weft_spacing_mm);
         set(w.warp_width_mm, o->w.warp_width_mm), set(w.weft_width_mm, o->w.weft_width_mm);
         set(w.warp_thickness_mm, o->w.warp_thickness_mm);
         set(w.weft_thickness_mm, o->w.weft_thickness_mm);
         set(w.warp_crimp_share, o->w.warp_crimp_share),
             set(w.fiber_radius_um, o->w.fiber_radius_um);
         set(w.packing, o->w.packing), set(w.twist_per_mm, o->w.twist_per_mm);
         set(w.twist_angle_deg, o->w.twist_angle_deg),
             set(w.ply_twist_per_mm, o->w.ply_twist_per_mm);
         if (o->w.fibers_per_yarn) w.fibers_per_yarn = o->w.fibers_per_yarn, w.packing.reset();
         if (o->w.packing) w.fibers_per_yarn.reset();
         if (o->w.plies) w.plies = o->w.plies;
         if (o->w.twist_angle_deg && !o->w.twist_per_mm) w.twist_per_mm.reset();
         if (o->w.twist_per_mm && !o->w.twist_angle_deg) w.twist_angle_deg.reset();
         // A WIF draft brings its own sizes: only those given here (not the bundled ones) override.
         if (!w.wif.empty() && o->sample.empty()) {
           auto keep_given = [](std::optional<double>& v, bool given) {
             if (!given) v.reset();
           };
           keep_given(w.warp_spacing_mm, given("--warp-spacing-mm"));
           keep_given(w.weft_spacing_mm, given("--weft-spacing-mm"));
           keep_given(w.warp_width_mm, given("--warp-width-mm") || given("--yarn-width-mm"));
           keep_given(w.weft_width_mm, given("--weft-width-mm") || given("--yarn-width-mm"));
           keep_given(w.warp_thickness_mm,
                      given("--warp-thickness-mm") || given("--yarn-thickness-mm"));
           keep_given(w.weft_thickness_mm,
                      given("--weft-thickness-mm") || given("--yarn-thickness-mm"));
           keep_given(w.warp_crimp_share, given("--warp-crimp-share"));
         }
         const WovenSample sample = make_woven_sample(w);
         write_woven(o->output, sample);
         const WeaveSummary& s = sample.summary;
         if (o->json) {
           std::cout << weave_summary_json(s, o->output);
         } else {
           std::printf("%s: %s detail, %s; period %.4f x %.4f mm (x by z), y in [%.4f, %.4f] mm; ",
                       o->output.c_str(), s.detail.c_str(), s.source.c_str(), s.period_x_mm,
                       s.period_z_mm, s.y_min_mm, s.y_max_mm);
           if (s.detail == "yarn")
             std::printf("%zu triangles\n", s.triangles);
           else
             std::printf("%zu curves, %zu segments; closest fibers %.2f um apart\n", s.curves,
                         s.curve_segments, s.min_fiber_distance_um);
           if (!s.floating_warps.empty() || !s.floating_wefts.empty())
             std::printf("note: %zu warp and %zu weft threads never interlace (floating threads)\n",
                         s.floating_warps.size(), s.floating_wefts.size());
         }
         return 0;
       }});
}

}  // namespace weft::cli
