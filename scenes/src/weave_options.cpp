// Weave options: the bundled red-cotton poplin's, one options file laid over another, and the
// reader of a weave options file (`weft weave --sample`, `weft bake fabric --weave`).
#include <fstream>
#include <sstream>

#include "weave_internal.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/scenes/weave.h"

namespace weft {

using namespace detail::red_cotton;

WeaveOptions red_cotton_weave_options() {
  WeaveOptions o;
  o.pattern = "plain";
  o.detail = "yarn";
  o.repeats_x = o.repeats_z = 1;
  o.warp_spacing_mm = kRedWarpSpacing;
  o.weft_spacing_mm = kRedWeftSpacing;
  o.warp_width_mm = kRedWarpWidth;
  o.weft_width_mm = kRedWeftWidth;
  o.warp_thickness_mm = kRedWarpThickness;
  o.weft_thickness_mm = kRedWeftThickness;
  o.warp_crimp_share = kRedWarpCrimpShare;
  o.segments_per_crossing = 16;
  o.sides = 16;
  o.fiber_radius_um = kRedFiberRadiusUm;
  o.packing = kRedPacking;
  o.plies = 1;
  o.twist_per_mm = kRedTwistPerMm;
  return o;
}

WeaveOptions overlay(WeaveOptions base, const WeaveOptions& g) {
  auto take = [](auto& dst, const auto& src) {
    if (src) dst = src;
  };
  if (g.pattern) base.wif.reset();
  if (g.wif) base.pattern.reset();
  if (g.fibers_per_yarn) base.packing.reset();
  if (g.packing) base.fibers_per_yarn.reset();
  if (g.twist_per_mm) base.twist_angle_deg.reset();
  if (g.twist_angle_deg) base.twist_per_mm.reset();
  take(base.pattern, g.pattern), take(base.wif, g.wif), take(base.detail, g.detail);
  take(base.repeats_x, g.repeats_x), take(base.repeats_z, g.repeats_z);
  take(base.warp_spacing_mm, g.warp_spacing_mm), take(base.weft_spacing_mm, g.weft_spacing_mm);
  take(base.warp_width_mm, g.warp_width_mm), take(base.weft_width_mm, g.weft_width_mm);
  take(base.warp_thickness_mm, g.warp_thickness_mm);
  take(base.weft_thickness_mm, g.weft_thickness_mm);
  take(base.warp_crimp_share, g.warp_crimp_share);
  take(base.segments_per_crossing, g.segments_per_crossing), take(base.sides, g.sides);
  take(base.fiber_radius_um, g.fiber_radius_um), take(base.fibers_per_yarn, g.fibers_per_yarn);
  take(base.packing, g.packing), take(base.plies, g.plies);
  take(base.twist_per_mm, g.twist_per_mm), take(base.twist_angle_deg, g.twist_angle_deg);
  take(base.ply_twist_per_mm, g.ply_twist_per_mm);
  if (g.thickness_mm) base.solidity.reset();
  if (g.solidity) base.thickness_mm.reset();
  take(base.areal_density_gsm, g.areal_density_gsm), take(base.thickness_mm, g.thickness_mm);
  take(base.solidity, g.solidity), take(base.inclination_sd_deg, g.inclination_sd_deg);
  take(base.fiber_length_mm, g.fiber_length_mm), take(base.tile_mm, g.tile_mm);
  take(base.fiber_density_g_cm3, g.fiber_density_g_cm3), take(base.seed, g.seed);
  return base;
}

WeaveOptions read_weave_options(ParamReader& r, const std::filesystem::path& base_dir) {
  WeaveOptions o;
  const double big = 1e300;
  if (r.has("description")) r.string("description");
  if (r.has("pattern")) o.pattern = r.string("pattern");
  if (r.has("wif")) {
    const std::filesystem::path p = r.string("wif");
    o.wif = (p.is_absolute() ? p : base_dir / p).string();
    r.reject_unused("pattern", "a WIF draft gives the pattern");
  }
  if (r.has("detail")) o.detail = r.choice("detail", "yarn", {"yarn", "fiber"});
  if (r.has("repeats")) {
    const auto& a = r.at("repeats");
    if (!a.is_array() || a.size() != 2)
      throw Error(r.file(), r.field("repeats"), "must be [nx, nz]");
    o.repeats_x = static_cast<int>(r.check_number(a[0], r.field("repeats") + "[0]", 1, 1000));
    o.repeats_z = static_cast<int>(r.check_number(a[1], r.field("repeats") + "[1]", 1, 1000));
  }
  auto num = [&](const char* key, std::optional<double>& v) {
    if (r.has(key)) v = r.number(key, -big, big);
  };
  auto integer = [&](const char* key, std::optional<int>& v, int lo, int hi) {
    if (r.has(key)) v = static_cast<int>(r.integer(key, lo, hi));
  };
  num("warp-spacing-mm", o.warp_spacing_mm);
  num("weft-spacing-mm", o.weft_spacing_mm);
  num("warp-width-mm", o.warp_width_mm);
  num("weft-width-mm", o.weft_width_mm);
  num("warp-thickness-mm", o.warp_thickness_mm);
  num("weft-thickness-mm", o.weft_thickness_mm);
  num("warp-crimp-share", o.warp_crimp_share);
  integer("segments-per-crossing", o.segments_per_crossing, 2, 1024);
  integer("sides", o.sides, 4, 1024);
  num("fiber-radius-um", o.fiber_radius_um);
  integer("fibers-per-yarn", o.fibers_per_yarn, 1, 100000);
  num("packing", o.packing);
  integer("plies", o.plies, 1, 16);
  num("twist-per-mm", o.twist_per_mm);
  num("twist-angle-deg", o.twist_angle_deg);
  num("ply-twist-per-mm", o.ply_twist_per_mm);
  num("areal-density-gsm", o.areal_density_gsm);
  num("thickness-mm", o.thickness_mm);
  num("solidity", o.solidity);
  if (o.thickness_mm) r.reject_unused("solidity", "give thickness-mm or solidity, not both");
  num("inclination-sd-deg", o.inclination_sd_deg);
  num("fiber-length-mm", o.fiber_length_mm);
  num("tile-mm", o.tile_mm);
  num("fiber-density-g-cm3", o.fiber_density_g_cm3);
  if (r.has("seed")) o.seed = static_cast<uint64_t>(r.integer("seed", 0, int64_t(1) << 53));
  r.finish();
  return o;
}

WeaveOptions read_weave_options(const std::filesystem::path& json_file) {
  std::ifstream in(json_file, std::ios::binary);
  if (!in) throw Error(json_file.string(), "", "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = parse_json(text.str(), json_file.string());
  ParamReader r(j, json_file.string(), "");  // keeps a reference to j
  return read_weave_options(r, json_file.parent_path());
}

}  // namespace weft
