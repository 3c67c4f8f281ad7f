// The weave generator: options, yarn centre lines and lens sections, the crossing check, yarn
// tubes, and the legacy open-mesh patch. Reading options: weave_options.cpp; fibers:
// weave_fibers.cpp; glTF: weave_gltf.cpp.
#include "weft/scenes/weave.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "weave_internal.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/scenes/wif.h"

namespace weft {
namespace detail {

double lens_half_thickness(double w, double t, double l) {
  if (std::abs(l) >= 0.5 * w) return 0;
  return 0.5 * t * std::cos(kPi * l / w);
}

double YarnPath::height_at(double s, double* slope) const {
  const size_t n = crossing.size();
  // Reduce s into [start, start + period).
  double r = s - start;
  r -= period * std::floor(r / period);
  const double x = start + r;
  const size_t k =
      static_cast<size_t>(std::upper_bound(crossing.begin(), crossing.end(), x) - crossing.begin());
  // The crossings around x: c0 <= x < c1, wrapping around the period.
  const double c0 = k == 0 ? crossing[n - 1] - period : crossing[k - 1];
  const double h0 = k == 0 ? height[n - 1] : height[k - 1];
  const double c1 = k == n ? crossing[0] + period : crossing[k];
  const double h1 = k == n ? height[0] : height[k];
  const double u = (x - c0) / (c1 - c0);
  // Half cosine from h0 to h1: zero slope at both crossings.
  if (slope) *slope = (h1 - h0) * 0.5 * kPi / (c1 - c0) * std::sin(kPi * u);
  return h0 + (h1 - h0) * 0.5 * (1 - std::cos(kPi * u));
}

double YarnPath::max_slope() const {
  double m = 0;
  const size_t n = crossing.size();
  for (size_t k = 0; k < n; ++k) {
    const double c1 = k + 1 == n ? crossing[0] + period : crossing[k + 1];
    const double h1 = k + 1 == n ? height[0] : height[k + 1];
    m = std::max(m, std::abs(h1 - height[k]) * 0.5 * kPi / (c1 - crossing[k]));
  }
  return m;
}

}  // namespace detail

using detail::kMetresPerMm;
using detail::Layout;
using detail::YarnPath;
using namespace detail::red_cotton;

namespace {

// Limits checked before anything is sized by them.
constexpr double kMaxTriangles = 5e7;
constexpr double kMaxCurvePoints = 3e7;

[[noreturn]] void bad(const std::string& field, const std::string& msg) {
  throw Error("", field, msg);
}

// 'where' names the source of a value that did not come from the options (a WIF thread).
double check_length(const std::optional<double>& v, double fallback, const std::string& field,
                    double lo, double hi, const std::string& where = "") {
  const double x = v.value_or(fallback);
  if (!(std::isfinite(x) && x > lo && x <= hi))
    bad(field, "must be finite and in (" + ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) +
                   "], got " + ParamReader::fmt(x) +
                   (v || where.empty() ? "" : " (" + where + ")"));
  return x;
}

// An error's message without its "field '...': " prefix, to nest it in another about that field.
std::string without_field(const std::string& what) {
  const auto at = what.find("': ");
  return what.rfind("field '", 0) == 0 && at != std::string::npos ? what.substr(at + 3) : what;
}

struct Resolved {
  std::string detail;
  int repeats_x = 1, repeats_z = 1;
  Layout layout;
  detail::FiberSettings fibers;
  bool fiber_detail = false;
  std::string source;
  std::vector<std::array<double, 3>> warp_rgb, weft_rgb;  // per repeat thread (WIF only)
  Interlacing repeat;
  double curve_points = 0, curves = 0;  // estimated (fiber detail)
};

// The detail, repeat counts and tessellation, checked; the tessellation goes to r.layout.
void resolve_detail(const WeaveOptions& o, Resolved& r) {
  r.detail = o.detail.value_or("yarn");
  if (r.detail != "yarn" && r.detail != "fiber")
    bad("detail", "must be yarn or fiber, got '" + r.detail + "'");
  r.fiber_detail = r.detail == "fiber";
  r.repeats_x = o.repeats_x.value_or(1);
  r.repeats_z = o.repeats_z.value_or(1);
  if (r.repeats_x < 1 || r.repeats_x > 1000 || r.repeats_z < 1 || r.repeats_z > 1000)
    bad("repeats", "each count must lie in [1, 1000]");
  const int segments_per_crossing = o.segments_per_crossing.value_or(16);
  const int sides = o.sides.value_or(16);
  if (segments_per_crossing < 2 || segments_per_crossing > 1024)
    bad("segments-per-crossing", "must lie in [2, 1024]");
  if (sides < 4 || sides > 1024) bad("sides", "must lie in [4, 1024]");
  r.layout.segments_per_crossing = segments_per_crossing;
  r.layout.sides = sides;
}

// The sizes of the repeat's threads, each way.
struct ThreadSizes {
  std::vector<ThreadSize> warp, weft;
};

// The repeat, its threads' sizes and colours from the WIF draft o.wif. A thread's thickness is
// its drawn width (clamped to its spacing so neighbours do not overlap); its height follows the
// red-cotton flattening unless given.
ThreadSizes wif_threads(const WeaveOptions& o, Resolved& r) {
  const WifDraft d = read_wif(*o.wif);
  r.repeat = d.interlacing();
  r.source = *o.wif;
  ThreadSizes sized;
  auto sizes = [&](const std::vector<WifThread>& threads, const std::string& dir,
                   const std::optional<double>& sp, const std::optional<double>& wd,
                   const std::optional<double>& th, double def_sp, double def_w, double flat,
                   std::vector<ThreadSize>& out, std::vector<std::array<double, 3>>& rgb) {
    for (const WifThread& t : threads) {
      const std::string where = *o.wif + ", " + dir + " thread " + std::to_string(out.size() + 1);
      ThreadSize s;
      s.spacing_mm = check_length(sp, t.spacing_mm > 0 ? t.spacing_mm : def_sp, dir + "-spacing-mm",
                                  0, 100, where);
      const double drawn = t.thickness_mm > 0 ? std::min(t.thickness_mm, s.spacing_mm)
                                              : std::min(def_w, s.spacing_mm);
      s.width_mm = check_length(wd, drawn, dir + "-width-mm", 0, 100, where);
      s.thickness_mm = check_length(th, s.width_mm * flat, dir + "-thickness-mm", 0, 100, where);
      out.push_back(s);
      rgb.push_back(t.rgb);
    }
  };
  const double warp_flat = kRedWarpThickness / kRedWarpWidth,
               weft_flat = kRedWeftThickness / kRedWeftWidth;
  sizes(d.warp, "warp", o.warp_spacing_mm, o.warp_width_mm, o.warp_thickness_mm, kRedWarpSpacing,
        kRedWarpWidth, warp_flat, sized.warp, r.warp_rgb);
  sizes(d.weft, "weft", o.weft_spacing_mm, o.weft_width_mm, o.weft_thickness_mm, kRedWeftSpacing,
        kRedWeftWidth, weft_flat, sized.weft, r.weft_rgb);
  return sized;
}

// The repeat of the named pattern; every thread of a direction has the options' size.
ThreadSizes pattern_threads(const WeaveOptions& o, Resolved& r) {
  r.repeat = parse_weave_pattern(o.pattern.value_or("plain"), "pattern");
  r.source = o.pattern.value_or("plain");
  ThreadSize w, f;
  w.spacing_mm = check_length(o.warp_spacing_mm, kRedWarpSpacing, "warp-spacing-mm", 0, 100);
  f.spacing_mm = check_length(o.weft_spacing_mm, kRedWeftSpacing, "weft-spacing-mm", 0, 100);
  w.width_mm = check_length(o.warp_width_mm, kRedWarpWidth, "warp-width-mm", 0, 100);
  f.width_mm = check_length(o.weft_width_mm, kRedWeftWidth, "weft-width-mm", 0, 100);
  w.thickness_mm =
      check_length(o.warp_thickness_mm, kRedWarpThickness, "warp-thickness-mm", 0, 100);
  f.thickness_mm =
      check_length(o.weft_thickness_mm, kRedWeftThickness, "weft-thickness-mm", 0, 100);
  ThreadSizes out;
  out.warp.assign(r.repeat.warps, w);
  out.weft.assign(r.repeat.wefts, f);
  return out;
}

// A yarn wider than its spacing would overlap its neighbours; the same check each way.
void check_widths(const std::vector<ThreadSize>& threads, const std::string& field,
                  const std::string& thread_name) {
  for (size_t k = 0; k < threads.size(); ++k)
    if (threads[k].width_mm > threads[k].spacing_mm * (1 + 1e-12))
      bad(field, thread_name + " " + std::to_string(k + 1) + " is wider (" +
                     ParamReader::fmt(threads[k].width_mm) + " mm) than its spacing (" +
                     ParamReader::fmt(threads[k].spacing_mm) +
                     " mm): neighbouring yarns would overlap");
}

// The tile's warps (along z) and picks (along x): the repeat's times the repeat counts.
double tile_warps(const Resolved& r) {
  return double(r.repeat.warps) * r.repeats_z;
}
double tile_wefts(const Resolved& r) {
  return double(r.repeat.wefts) * r.repeats_x;
}

// The yarn tubes' triangles, estimated before anything is allocated.
void check_triangle_count(const Resolved& r) {
  // Segments along all yarns.
  const double segs = double(r.layout.segments_per_crossing) * tile_warps(r) * tile_wefts(r) * 2;
  const int sides = r.layout.sides;
  if (!r.fiber_detail && segs * sides * 2 > kMaxTriangles)
    bad("repeats", "the sample would have " + ParamReader::fmt(segs * sides * 2) +
                       " triangles (limit 5e7): fewer repeats, sides or segments");
}

detail::FiberSettings fiber_settings(const WeaveOptions& o) {
  detail::FiberSettings fs;
  fs.radius_mm =
      check_length(o.fiber_radius_um, kRedFiberRadiusUm, "fiber-radius-um", 0.01, 1000) * 1e-3;
  fs.plies = o.plies.value_or(1);
  if (fs.plies < 1 || fs.plies > 16) bad("plies", "must lie in [1, 16]");
  fs.fibers_per_yarn = o.fibers_per_yarn.value_or(0);
  if (o.fibers_per_yarn && (fs.fibers_per_yarn < 1 || fs.fibers_per_yarn > 100000))
    bad("fibers-per-yarn", "must lie in [1, 100000]");
  if (o.fibers_per_yarn && o.packing)
    bad("packing", "give either --fibers-per-yarn or --packing, not both");
  fs.packing = o.packing.value_or(kRedPacking);
  fs.densest_if_needed = !o.packing && !o.fibers_per_yarn;
  if (!(std::isfinite(fs.packing) && fs.packing > 0 && fs.packing < 0.9069))
    bad("packing", "must lie in (0, 0.9069) (0.9069: hexagonal packing of equal circles)");
  if (o.twist_per_mm && o.twist_angle_deg)
    bad("twist-angle-deg", "give either --twist-per-mm or --twist-angle-deg, not both");
  fs.twist_per_mm = o.twist_per_mm.value_or(kRedTwistPerMm);
  if (!(std::isfinite(fs.twist_per_mm) && std::abs(fs.twist_per_mm) <= 100))
    bad("twist-per-mm", "must be finite and at most 100 turns per mm in magnitude");
  if (o.twist_angle_deg) {
    fs.twist_from_angle = true;
    fs.twist_angle_deg = *o.twist_angle_deg;
    if (!(std::isfinite(fs.twist_angle_deg) && std::abs(fs.twist_angle_deg) < 80))
      bad("twist-angle-deg", "must lie in (-80, 80) degrees");
  }
  fs.ply_twist_per_mm = o.ply_twist_per_mm.value_or(0);
  if (!(std::isfinite(fs.ply_twist_per_mm) && std::abs(fs.ply_twist_per_mm) <= 100))
    bad("ply-twist-per-mm", "must be finite and at most 100 turns per mm in magnitude");
  if (o.ply_twist_per_mm && fs.plies == 1) bad("ply-twist-per-mm", "needs --plies 2 or more");
  return fs;
}

// The fibers' curve points, estimated (fibers per yarn from the packing unless given) before
// anything is allocated; 'curves' gets the fibers' count.
double curve_point_count(const Resolved& r, const ThreadSizes& t, double* curves = nullptr) {
  const detail::FiberSettings& fs = r.fibers;
  const int segments_per_crossing = r.layout.segments_per_crossing;
  double points = 0, fibers = 0;
  auto count = [&](const std::vector<ThreadSize>& ts, double yarns_per_thread, double along) {
    for (const ThreadSize& s : ts) {
      const double area = 2 * s.width_mm * s.thickness_mm / kPi;  // lens
      const double n =
          fs.fibers_per_yarn > 0
              ? fs.fibers_per_yarn
              : std::max(1.0, std::round(fs.packing * area / (kPi * fs.radius_mm * fs.radius_mm)));
      points += n * yarns_per_thread * (along * segments_per_crossing + 1);
      fibers += n * yarns_per_thread;
    }
  };
  count(t.warp, r.repeats_z, tile_wefts(r));
  count(t.weft, r.repeats_x, tile_warps(r));
  if (curves) *curves = fibers;
  return points;
}

void check_curve_point_count(Resolved& r, const ThreadSizes& t) {
  const detail::FiberSettings& fs = r.fibers;
  const double points = r.curve_points = curve_point_count(r, t, &r.curves);
  if (points > kMaxCurvePoints)
    bad(fs.fibers_per_yarn > 0 ? "fibers-per-yarn" : "packing",
        "the sample would have " + ParamReader::fmt(points) +
            " curve points (limit 3e7): fewer repeats, fibers or segments");
}

// Centres of 'count' threads cycling through the repeat's sizes, laid side by side and centred
// on zero; 'period' is their total spacing. Warps lie along z, picks along x.
std::vector<double> thread_centres(const std::vector<ThreadSize>& sizes, int repeat, int count,
                                   double& period) {
  std::vector<double> c(count);
  double acc = 0;
  for (int k = 0; k < count; ++k) {
    const double sp = sizes[k % repeat].spacing_mm;
    c[k] = acc + 0.5 * sp;
    acc += sp;
  }
  period = acc;
  for (double& v : c) v -= 0.5 * period;
  return c;
}

// The tile's interlacing, thread centres and yarn centre lines, with the warps' share 'share' of
// each crossing's crimp (< 0: balanced).
void lay_out(Resolved& r, const ThreadSizes& t, double share) {
  const std::vector<ThreadSize>&warp = t.warp, &weft = t.weft;
  const double nwarp = tile_warps(r), nweft = tile_wefts(r);
  Layout& L = r.layout;
  L.tile.warps = static_cast<int>(nwarp);
  L.tile.wefts = static_cast<int>(nweft);
  L.tile.warp_over.resize(static_cast<size_t>(nwarp * nweft));
  for (int j = 0; j < L.tile.wefts; ++j)
    for (int i = 0; i < L.tile.warps; ++i)
      L.tile.warp_over[static_cast<size_t>(j) * L.tile.warps + i] =
          r.repeat.over(i % r.repeat.warps, j % r.repeat.wefts);
  const std::vector<double> zc = thread_centres(warp, r.repeat.warps, L.tile.warps, L.period_z);
  const std::vector<double> xc = thread_centres(weft, r.repeat.wefts, L.tile.wefts, L.period_x);
  const bool balanced = share < 0;
  L.warp_crimp_share = share;
  auto warp_height = [&](int i, int j) {
    const ThreadSize &w = warp[i % r.repeat.warps], &f = weft[j % r.repeat.wefts];
    return balanced ? 0.5 * f.thickness_mm : share * 0.5 * (w.thickness_mm + f.thickness_mm);
  };
  // Signed centre height of warp i (of_warp) or pick j where they cross: the warp carries
  // warp_height, the pick the rest of the crossing's crimp height, on the other side.
  auto crossing_height = [&](bool of_warp, int i, int j) {
    if (of_warp) return (L.tile.over(i, j) ? 1 : -1) * warp_height(i, j);
    const ThreadSize &w = warp[i % r.repeat.warps], &f = weft[j % r.repeat.wefts];
    const double total = 0.5 * (w.thickness_mm + f.thickness_mm);
    return (L.tile.over(i, j) ? -1 : 1) * (total - warp_height(i, j));
  };
  // One yarn per thread of the tile, both directions alike: a warp runs along x past the picks'
  // centres, a pick along z past the warps'. Warps first (Layout::yarns' order).
  for (const bool is_warp : {true, false}) {
    const int count = is_warp ? L.tile.warps : L.tile.wefts;
    const int crossings = is_warp ? L.tile.wefts : L.tile.warps;
    for (int k = 0; k < count; ++k) {
      YarnPath y;
      y.warp = is_warp;
      y.thread = k % (is_warp ? r.repeat.warps : r.repeat.wefts);
      y.centre = (is_warp ? zc : xc)[k];
      y.size = (is_warp ? warp : weft)[y.thread];
      y.period = is_warp ? L.period_x : L.period_z;
      y.start = -0.5 * y.period;
      y.crossing = is_warp ? xc : zc;
      for (int c = 0; c < crossings; ++c)
        y.height.push_back(is_warp ? crossing_height(true, k, c) : crossing_height(false, c, k));
      L.yarns.push_back(std::move(y));
    }
  }
  if (balanced) L.warp_crimp_share = -1;
}

// The nonwoven mat's options have no meaning for a woven sample.
void check_no_nonwoven_options(const WeaveOptions& o) {
  const std::pair<bool, const char*> given[] = {
      {o.areal_density_gsm.has_value(), "areal-density-gsm"},
      {o.thickness_mm.has_value(), "thickness-mm"},
      {o.solidity.has_value(), "solidity"},
      {o.inclination_sd_deg.has_value(), "inclination-sd-deg"},
      {o.fiber_length_mm.has_value(), "fiber-length-mm"},
      {o.tile_mm.has_value(), "tile-mm"},
      {o.fiber_density_g_cm3.has_value(), "fiber-density-g-cm3"},
      {o.seed.has_value(), "seed"}};
  for (const auto& [set, field] : given)
    if (set) bad(field, std::string("only with --pattern ") + kNonwovenPattern);
}

Resolved resolve(const WeaveOptions& o) {
  check_no_nonwoven_options(o);
  Resolved r;
  resolve_detail(o, r);
  if (o.wif && o.pattern) bad("wif", "give either a pattern or a WIF draft, not both");
  const bool from_wif = o.wif.has_value();
  const ThreadSizes threads = from_wif ? wif_threads(o, r) : pattern_threads(o, r);
  check_widths(threads.warp, "warp-width-mm", "warp");
  check_widths(threads.weft, "weft-width-mm", "pick");
  // A WIF draft's threads have no crimp data: balanced unless given.
  const double share = o.warp_crimp_share.value_or(from_wif ? -1.0 : kRedWarpCrimpShare);
  if (!std::isfinite(share) || share > 1) bad("warp-crimp-share", "must be <= 1 (< 0: balanced)");
  check_triangle_count(r);
  r.fibers = fiber_settings(o);
  if (r.fiber_detail) check_curve_point_count(r, threads);
  lay_out(r, threads, share);
  return r;
}

// The smallest separation over the crossing of warp i and pick j: the upper yarn's lower surface
// above the lower yarn's upper surface, sampled densely (the model makes it zero at the centre).
// 'slope_grown': each lens grown by sqrt(1 + slope^2) where the centre line slopes, as a bundle
// of fibers in sections perpendicular to the yarn stands taller than its tube.
double crossing_separation(const Layout& L, int i, int j, bool slope_grown) {
  constexpr int kN = 24;
  const YarnPath &w = L.yarns[i], &f = L.yarns[L.tile.warps + j];
  const bool warp_over = L.tile.over(i, j);
  double worst = 1e300;
  for (int a = 0; a <= kN; ++a)
    for (int b = 0; b <= kN; ++b) {
      const double dx = f.size.width_mm * (double(a) / kN - 0.5);
      const double dz = w.size.width_mm * (double(b) / kN - 0.5);
      const double x = f.centre + dx, z = w.centre + dz;
      double sw = 0, sf = 0;
      const double hw = w.height_at(x, &sw), hf = f.height_at(z, &sf);
      const double ew = detail::lens_half_thickness(w.size.width_mm, w.size.thickness_mm, dz) *
                        (slope_grown ? std::sqrt(1 + sw * sw) : 1.0);
      const double ef = detail::lens_half_thickness(f.size.width_mm, f.size.thickness_mm, dx) *
                        (slope_grown ? std::sqrt(1 + sf * sf) : 1.0);
      worst = std::min(worst, warp_over ? (hw - ew) - (hf + ef) : (hf - ef) - (hw + ew));
    }
  return worst;
}

// Every crossing of the repeat: the tubes must not interpenetrate anywhere over it. Error naming
// the share otherwise.
void check_crossings(const Layout& L, int repeat_warps, int repeat_wefts) {
  for (int i = 0; i < repeat_warps; ++i)
    for (int j = 0; j < repeat_wefts; ++j) {
      const YarnPath &w = L.yarns[i], &f = L.yarns[L.tile.warps + j];
      const double tol = 1e-9 * (w.size.thickness_mm + f.size.thickness_mm);
      const double worst = crossing_separation(L, i, j, false);
      if (worst < -tol)
        bad("warp-crimp-share",
            "warp " + std::to_string(i + 1) + " and pick " + std::to_string(j + 1) +
                " would interpenetrate by " + ParamReader::fmt(-worst * 1e3) +
                " um at this crimp share (" + ParamReader::fmt(L.warp_crimp_share) +
                "); move it towards the balanced value (-1), or make the crossing yarns narrower "
                "than their spacing");
    }
}

// Whether the fibers keep their distances in sections perpendicular to the yarns, which
// make_woven_sample tries first (then vertical sections, sparser): each crossing checked as
// check_crossings checks the tubes, each lens grown by the slope, against the fibers' clearance
// (2 % of a radius). A prediction before anything is built; the bundled samples and drafts end in
// the sections it predicts (test_mesh_shifts.cpp).
bool perpendicular_sections_fit(const Layout& L, int repeat_warps, int repeat_wefts,
                                double radius_mm) {
  for (int i = 0; i < repeat_warps; ++i)
    for (int j = 0; j < repeat_wefts; ++j)
      if (crossing_separation(L, i, j, true) < -0.02 * radius_mm) return false;
  return true;
}

// One tube: rings k = 0..K along, vertices j = 0..M around (the seam repeats j = 0), triangles
// (a, d, b), (b, d, c) with a = (k, j), d = (k, j + 1), b = (k + 1, j): front-facing outwards when
// dP/dv x dP/du points out.
struct TubeVertex {
  Vec3 p, n, t;
  double w = 1, u = 0, v = 0;
};
// A tube of the largest sample holds a good part of its 5e7 triangles (one yarn of 1000 repeats),
// so 'keep_going' (given the rings made) is asked between rings, about every 64 k vertices: a few
// milliseconds of work. Each ring's triangles follow it, so a stop leaves whole rings; the order
// of vertices and triangles is the same either way. Returns false when stopped.
constexpr int kTubeVerticesPerPoll = 1 << 16;
bool append_tube(TriangleMesh& m, int K, int M,
                 const std::function<TubeVertex(int k, int j)>& vertex,
                 const std::function<bool(int rings)>& keep_going = {}) {
  auto push3 = [](std::vector<float>& v, const Vec3& p) {
    v.push_back(static_cast<float>(p.x));
    v.push_back(static_cast<float>(p.y));
    v.push_back(static_cast<float>(p.z));
  };
  const auto base = static_cast<uint32_t>(m.vertex_count());
  const int rings_per_poll = std::max(1, kTubeVerticesPerPoll / (M + 1));
  for (int k = 0; k <= K; ++k) {
    if (keep_going && k % rings_per_poll == 0 && !keep_going(k)) return false;
    for (int j = 0; j <= M; ++j) {
      const TubeVertex v = vertex(k, j);
      push3(m.positions, v.p);
      push3(m.normals, v.n);
      push3(m.tangents, v.t);
      m.tangents.push_back(static_cast<float>(v.w));
      m.uvs.push_back(static_cast<float>(v.u));
      m.uvs.push_back(static_cast<float>(v.v));
    }
    if (k == 0) continue;
    for (int j = 0; j < M; ++j) {  // the quads between ring k - 1 and ring k
      const uint32_t a = base + (k - 1) * (M + 1) + j, b = a + (M + 1), c = b + 1, d = a + 1;
      m.indices.insert(m.indices.end(), {a, d, b, b, d, c});
    }
  }
  return true;
}

// A yarn of the woven sample as a closed lens tube. Angles run clockwise seen along the yarn
// (phi = -2 pi (j + 1/2) / M) so that dP/dv x dP/du points outwards; no vertex sits on a lens
// tip, so the polygon is inscribed in the (convex) lens.
bool append_yarn_tube(TriangleMesh& m, const YarnPath& y, int segments_per_crossing, int M,
                      const std::function<bool(int rings)>& keep_going) {
  const int K = static_cast<int>(y.crossing.size()) * segments_per_crossing;
  const double w = y.size.width_mm, t = y.size.thickness_mm;
  const Vec3 up{0, 1, 0};
  const auto vertex = [&](int k, int j) {
    const double s = y.start + y.period * (k % K) / K;  // ring K repeats ring 0, shifted
    const double shift = k == K ? y.period : 0;
    double slope = 0;
    const double h = y.height_at(s, &slope);
    const double phi = -2 * kPi * ((j % M) + 0.5) / M;
    const double c = std::cos(phi), sn = std::sin(phi), sg = sn < 0 ? -1.0 : 1.0;
    const double l = 0.5 * w * c;
    const double yo = 0.5 * t * sg * std::cos(0.5 * kPi * c);
    // Derivatives in phi (for the normal) and s.
    const double dl = -0.5 * w * sn;
    const double dy = 0.5 * t * 0.5 * kPi * std::abs(sn) * std::sin(0.5 * kPi * c);
    const Vec3 dp_ds = y.along() + up * slope;
    const Vec3 dp_dphi = y.lateral() * dl + up * dy;
    Vec3 n = normalize(cross(dp_dphi, dp_ds));
    const Vec3 offset = y.lateral() * l + up * yo;
    if (dot(n, offset) < 0) n = -n;  // outwards (the section is convex about the centre)
    TubeVertex v;
    v.p = (y.along() * (s + shift) + y.across() * y.centre + up * (h + yo) + y.lateral() * l) *
          kMetresPerMm;
    v.n = n;
    v.t = normalize(dp_ds - n * dot(dp_ds, n));
    // glTF: bitangent = cross(normal, tangent) * w points along dP/dv = -dP/dphi.
    v.w = dot(cross(v.n, v.t), dp_dphi) <= 0 ? 1.0 : -1.0;
    v.u = double(k) / K;
    v.v = double(j) / M;
    return v;
  };
  return append_tube(m, K, M, vertex, keep_going);
}

void check_legacy(const WeaveParams& p) {
  if (p.pattern != "plain") bad("pattern", "unknown pattern '" + p.pattern + "' (valid: plain)");
  if (p.yarns < 1 || p.yarns > 4096) bad("yarns", "must lie in [1, 4096]");
  if (!(std::isfinite(p.yarn_radius_mm) && p.yarn_radius_mm > 0 && p.yarn_radius_mm < 1e3))
    bad("yarn-radius-mm", "must be finite and in (0, 1000)");
  if (!(std::isfinite(p.spacing_mm) && p.spacing_mm < 1e4)) bad("spacing-mm", "must be finite");
  if (!(p.spacing_mm >= 2 * p.yarn_radius_mm))
    bad("spacing-mm", "must be at least twice the yarn radius (parallel yarns would overlap)");
  if (p.segments < 2 || p.segments > (1 << 20)) bad("segments", "must lie in [2, 2^20]");
  if (p.sides < 3 || p.sides > 1024) bad("sides", "must lie in [3, 1024]");
  if (!std::isfinite(p.amplitude_mm) || p.amplitude_mm > 1e3) bad("amplitude-mm", "must be finite");
  const double tris = 2.0 * p.yarns * p.segments * p.sides * 2.0;
  if (tris > 2e9) bad("segments", "the patch would exceed 2e9 triangles");
}

// Legacy: a circular tube around a sinusoidal centre line; 'along' is the yarn axis, 'across'
// the in-plane offset axis, 'offset' its position there; the centre rises as
// sign * A * cos(pi (s - s0) / S).
void append_legacy_yarn(TriangleMesh& m, const WeaveParams& p, const Vec3& along,
                        const Vec3& across, double offset, double sign) {
  const double S = p.spacing_mm * kMetresPerMm, R = p.yarn_radius_mm * kMetresPerMm;
  const double A = (p.amplitude_mm < 0 ? p.yarn_radius_mm : p.amplitude_mm) * kMetresPerMm;
  const double L = p.yarns * S, s0 = -0.5 * (p.yarns - 1) * S;
  const Vec3 up{0, 1, 0};
  const Vec3 U = cross(along, up);  // perpendicular to the centre line's plane
  const int K = p.segments, M = p.sides;
  append_tube(m, K, M, [&](int k, int j) {
    const double s = -0.5 * L + L * k / K;
    const double phase = kPi * (s - s0) / S;
    const Vec3 c = along * s + across * offset + up * (sign * A * std::cos(phase));
    const Vec3 T = normalize(along + up * (-sign * A * (kPi / S) * std::sin(phase)));
    const Vec3 V = cross(T, U);
    const double th = 2 * kPi * (j % M) / M;  // the seam repeats the first column exactly
    const Vec3 r = U * std::cos(th) + V * std::sin(th);
    TubeVertex v;
    v.p = c + r * R;
    v.n = r;
    v.t = T;
    v.w = -1;  // glTF: bitangent = cross(normal, tangent) * w; dP/dv points along -cross(r, T)
    v.u = static_cast<double>(k) / K;
    v.v = static_cast<double>(j) / M;
    return v;
  });
}

void add_once(std::vector<std::string>& notes, const std::string& note) {
  if (std::find(notes.begin(), notes.end(), note) == notes.end()) notes.push_back(note);
}

// A note per thread size whose section took the densest packing it admits instead of the
// default one (sizes that came out alike, once).
std::vector<std::string> packing_notes(const WeaveSummary& s) {
  std::vector<std::string> notes;
  for (const bool warp : {true, false})
    for (const FiberLayoutInfo& f : warp ? s.warp_fibers : s.weft_fibers)
      if (f.default_packing > 0)
        add_once(notes, std::string(warp ? "warp" : "weft") + ": the default packing " +
                            ParamReader::fmt(f.default_packing) +
                            " does not fit; the densest packing that fits, " +
                            ParamReader::fmt(std::round(f.packing * 1000) / 1000) + " (" +
                            std::to_string(f.fibers) + " fibers per yarn), was taken");
  return notes;
}

nlohmann::json summary_object(const WeaveSummary& s) {
  auto fibers = [](const std::vector<FiberLayoutInfo>& v) {
    auto a = nlohmann::json::array();
    for (const auto& f : v)
      a.push_back({{"fibers_per_yarn", f.fibers},
                   {"packing", f.packing},
                   {"twist_per_mm", f.twist_per_mm},
                   {"twist_angle_deg", f.twist_angle_deg}});
    return a;
  };
  nlohmann::json j = {
      {"source", s.source},
      {"detail", s.detail},
      {"repeat_threads", {{"warps", s.warps}, {"wefts", s.wefts}}},
      {"repeats", {{"x", s.repeats_x}, {"z", s.repeats_z}}},
      {"repeat_mm", {{"x", s.repeat_x_mm}, {"z", s.repeat_z_mm}}},
      {"period_mm", {{"x", s.period_x_mm}, {"z", s.period_z_mm}}},
      {"thickness_mm", {{"y_min", s.y_min_mm}, {"y_max", s.y_max_mm}}},
      {"warp_crimp_share", s.warp_crimp_share},
      {"floating_threads", {{"warps", s.floating_warps}, {"wefts", s.floating_wefts}}},
      {"triangles", s.triangles},
      {"vertices", s.vertices},
      {"curves", s.curves},
      {"curve_segments", s.curve_segments},
      {"curve_points", s.curve_points},
      {"units", "metres in the glTF; mm and um here as named"}};
  if (s.detail == "fiber") {
    j["fibers"] = {{"warp", fibers(s.warp_fibers)}, {"weft", fibers(s.weft_fibers)}};
    j["min_fiber_distance_um"] = s.min_fiber_distance_um;
    j["fiber_sections"] = s.fiber_sections;
  }
  if (!s.notes.empty()) j["notes"] = s.notes;
  if (s.nonwoven) {
    const NonwovenSummary& n = *s.nonwoven;
    j["nonwoven"] = {{"areal_density_gsm", n.areal_density_gsm},
                     {"thickness_mm", n.thickness_mm},
                     {"solidity", n.solidity},
                     {"fiber_length_mm", n.fiber_length_mm},
                     {"fiber_density_g_cm3", n.fiber_density_g_cm3},
                     {"inclination_sd_deg", n.inclination_sd_deg},
                     {"fibers", n.fibers},
                     {"attempts", n.attempts},
                     {"seed", n.seed}};
    j["min_fiber_distance_um"] = s.min_fiber_distance_um;
  }
  return j;
}

}  // namespace

WovenSampleSize woven_sample_size(const WeaveOptions& options) {
  WovenSampleSize z;
  if (options.pattern == kNonwovenPattern) {  // a mat (nonwoven.h): straight pieces, two points
    const NonwovenSize n = nonwoven_sample_size(options);
    z.detail = "fiber";
    z.curves = n.curves, z.curve_points = 2 * n.curves, z.curve_segments = n.curves;
    z.made_curve_points = z.curve_points, z.made_curve_segments = z.curve_segments;
    z.placement_crossing_checks = n.crossing_checks, z.placement_copy_checks = n.copy_checks;
    return z;
  }
  const Resolved r = resolve(options);
  const Layout& L = r.layout;
  z.detail = r.detail;
  z.sides = L.sides;
  z.segments_per_crossing = L.segments_per_crossing;
  if (r.fiber_detail) {
    z.curves = r.curves, z.curve_points = r.curve_points;
    z.curve_segments = r.curve_points - r.curves;
    // What make_woven_sample will hold: the sections predicted and the bundles' own counts
    // (8452.wif: 7.26 M points at the default packing, 4.0 M made in vertical sections). A bundle
    // that does not fit is make_woven_sample's error to report, with its fallback's words.
    detail::FiberSettings fs = r.fibers;
    fs.perpendicular =
        perpendicular_sections_fit(L, r.repeat.warps, r.repeat.wefts, r.fibers.radius_mm);
    z.fiber_sections = fs.perpendicular ? "perpendicular" : "vertical";
    try {
      const detail::FiberCount n = detail::count_fibers(L, fs);
      z.made_curve_points = n.points, z.made_curve_segments = n.points - n.curves;
    } catch (const Error&) {
      z.made_curve_points = z.curve_points, z.made_curve_segments = z.curve_segments;
    }
    return z;
  }
  // Each yarn a tube of K = crossings x segments rings of M sides (append_yarn_tube).
  for (const YarnPath& y : L.yarns) {
    const double K = double(y.crossing.size()) * L.segments_per_crossing, M = L.sides;
    z.triangles += 2 * K * M;
    z.vertices += (K + 1) * (M + 1);
  }
  return z;
}

namespace {

// Yarn detail: the warp and weft meshes into out.meshes, every yarn a tube (append_yarn_tube).
// The largest sample (5e7 triangles) takes tens of seconds, so 'progress' is told the vertices
// made and asked whether to go on every few milliseconds of work; false when it said stop (then
// out.cancelled, the meshes partial).
bool add_yarn_tubes(const Layout& L, WovenSample& out, const ProgressCallback& progress) {
  TriangleMesh warp, weft;
  warp.material = "warp";
  warp.names = {"warp", "patch"};
  weft.material = "weft";
  weft.names = {"weft", "patch"};
  const uint64_t ring = uint64_t(L.sides) + 1;
  // Reserved whole: a vector of a gigabyte that grew would copy itself between two polls.
  std::array<uint64_t, 2> vertices{}, quads{};  // warp, weft
  for (const YarnPath& y : L.yarns) {
    const uint64_t K = y.crossing.size() * L.segments_per_crossing;
    vertices[y.warp ? 0 : 1] += (K + 1) * ring;
    quads[y.warp ? 0 : 1] += K * L.sides;
  }
  const uint64_t total = vertices[0] + vertices[1];
  uint64_t before = 0;  // vertices of the tubes made
  for (int i = 0; i < 2; ++i) {
    TriangleMesh& m = i == 0 ? warp : weft;
    m.positions.reserve(3 * vertices[i]);
    m.normals.reserve(3 * vertices[i]);
    m.tangents.reserve(4 * vertices[i]);
    m.uvs.reserve(2 * vertices[i]);
    m.indices.reserve(6 * quads[i]);
  }
  for (const YarnPath& y : L.yarns) {
    const auto keep_going = [&](int rings) {
      return progress({"woven sample", before + uint64_t(rings) * ring, total, "vertices"});
    };
    if (!append_yarn_tube(y.warp ? warp : weft, y, L.segments_per_crossing, L.sides, keep_going)) {
      out.cancelled = true;
      return false;
    }
    before += (y.crossing.size() * L.segments_per_crossing + 1) * ring;
  }
  out.meshes.push_back(std::move(warp));
  out.meshes.push_back(std::move(weft));
  return true;
}

}  // namespace

WovenSample make_woven_sample(const WeaveOptions& options, const ProgressCallback& progress) {
  if (options.pattern == kNonwovenPattern) return make_nonwoven_sample(options, progress);
  const auto t0 = std::chrono::steady_clock::now();
  Resolved r = resolve(options);
  const Layout& L = r.layout;
  check_crossings(L, r.repeat.warps, r.repeat.wefts);

  WovenSample out;
  WeaveSummary& s = out.summary;
  s.source = r.source;
  s.detail = r.detail;
  s.warps = r.repeat.warps;
  s.wefts = r.repeat.wefts;
  s.repeats_x = r.repeats_x;
  s.repeats_z = r.repeats_z;
  s.period_x_mm = L.period_x;
  s.period_z_mm = L.period_z;
  s.repeat_x_mm = L.period_x / r.repeats_x;
  s.repeat_z_mm = L.period_z / r.repeats_z;
  s.warp_crimp_share = L.warp_crimp_share;
  s.floating_warps = r.repeat.floating_warps();
  s.floating_wefts = r.repeat.floating_wefts();
  if (!r.warp_rgb.empty()) {
    for (int i = 0; i < L.tile.warps; ++i) out.yarn_rgb.push_back(r.warp_rgb[i % s.warps]);
    for (int j = 0; j < L.tile.wefts; ++j) out.yarn_rgb.push_back(r.weft_rgb[j % s.wefts]);
  }
  double ylo = 1e300, yhi = -1e300;
  if (!r.fiber_detail) {
    if (!add_yarn_tubes(L, out, progress)) return out;
    for (const TriangleMesh& m : out.meshes) {
      s.triangles += m.triangle_count();
      s.vertices += m.vertex_count();
      const Bounds3 b = m.bounds();
      ylo = std::min(ylo, b.lo.y);
      yhi = std::max(yhi, b.hi.y);
    }
  } else {
    const double r_m = r.fibers.radius_mm * kMetresPerMm;
    // Perpendicular sections pack denser, but where the centre line slopes the bundle stands
    // taller than the tube by sqrt(1 + slope^2); crossings pressed together along their whole
    // length (balanced crimp, yarns as wide as their spacing) have no room for that, and the
    // measurement finds it. Then the fibers go in vertical sections, within the tubes.
    auto asker = [&](std::string_view stage, std::string_view unit) {
      return detail::sample_asker(out, progress, stage, unit);
    };
    double d = 0;
    for (const bool perpendicular : {true, false}) {
      out.fibers = FiberCurves{};
      s.warp_fibers.clear();
      s.weft_fibers.clear();
      r.fibers.perpendicular = perpendicular;
      try {
        detail::build_fibers(L, r.fibers, out.fibers, s.warp_fibers, s.weft_fibers,
                             asker("woven sample", "yarns"));
        if (out.cancelled) return out;
      } catch (const Error& e) {
        if (perpendicular) throw;
        bad(options.fibers_per_yarn ? "fibers-per-yarn" : "packing",
            "in sections perpendicular to the yarns the fibers would interpenetrate (" +
                ParamReader::fmt(s.min_fiber_distance_um) +
                " um apart); in vertical sections: " + without_field(e.what()));
      }
      d = min_fiber_distance(out.fibers, L.period_x * kMetresPerMm, L.period_z * kMetresPerMm,
                             4 * r_m, asker("fiber distances", "cells"));
      if (out.cancelled) return out;
      s.min_fiber_distance_um = d * 1e6;
      s.fiber_sections = perpendicular ? "perpendicular" : "vertical";
      // The layout keeps 2r plus a margin; refuse anything that still comes closer.
      if (d >= 2 * r_m * (1 - 1e-2)) break;
    }
    if (d < 2 * r_m * (1 - 1e-2))
      bad(options.fibers_per_yarn ? "fibers-per-yarn" : "packing",
          "fibers would interpenetrate: closest centre lines " + ParamReader::fmt(d * 1e6) +
              " um apart, less than twice the fiber radius; use fewer fibers, less twist or "
              "more segments per crossing");
    out.fibers.names = {"patch"};
    s.notes = packing_notes(s);
    const FiberCurves& f = out.fibers;
    s.curves = f.curve_count();
    s.curve_points = f.point_count();
    s.curve_segments = f.segment_count();
    for (size_t i = 0; i < f.point_count(); ++i) {
      ylo = std::min(ylo, f.point(i).y - f.radius(i));
      yhi = std::max(yhi, f.point(i).y + f.radius(i));
    }
  }
  s.y_min_mm = ylo / kMetresPerMm;
  s.y_max_mm = yhi / kMetresPerMm;
  s.seconds = seconds_since(t0);
  return out;
}

std::string weave_summary_json(const WeaveSummary& summary, const std::string& output) {
  nlohmann::json j = summary_object(summary);
  j["output"] = output;
  j["seconds"] = summary.seconds;
  return j.dump(2) + "\n";
}

namespace {
detail::GltfDocument woven_document(const WovenSample& sample) {
  nlohmann::json extras = summary_object(sample.summary);
  if (sample.summary.detail == "fiber")
    extras["fiber_encoding"] =
        "one LINE_STRIP primitive per fiber: POSITION (metres) and _RADIUS (SCALAR float, "
        "metres, per point); one node and mesh per yarn";
  extras["frame"] =
      "y up (face side), warp along x, weft along z; periodic in x and z with period_mm";
  return detail::build_gltf(sample.meshes.empty() ? nullptr : &sample.meshes,
                            sample.meshes.empty() ? &sample.fibers : nullptr, extras,
                            sample.yarn_rgb);
}
}  // namespace

std::string woven_to_gltf(const WovenSample& sample) {
  return detail::gltf_text(woven_document(sample));
}
std::vector<uint8_t> woven_to_glb(const WovenSample& sample) {
  return detail::glb_bytes(woven_document(sample));
}
void write_woven(const std::filesystem::path& path, const WovenSample& sample) {
  detail::write_gltf(path, woven_document(sample));
}

// ---------------------------------------------------------------------------------------------
// Legacy open-mesh patch.

std::vector<TriangleMesh> make_weave(const WeaveParams& p) {
  check_legacy(p);
  const double S = p.spacing_mm * kMetresPerMm;
  const double first = -0.5 * (p.yarns - 1) * S;
  TriangleMesh warp, weft;
  warp.material = "warp";
  warp.names = {"warp", "patch"};
  weft.material = "weft";
  weft.names = {"weft", "patch"};
  // Warp j runs along x at z_j; weft i along z at x_i. At crossing (i, j) the warp centre is at
  // +A (-1)^(i+j) and the weft centre at -A (-1)^(i+j): they alternate over and under.
  for (int j = 0; j < p.yarns; ++j)
    append_legacy_yarn(warp, p, {1, 0, 0}, {0, 0, 1}, first + j * S, (j % 2) ? -1.0 : 1.0);
  for (int i = 0; i < p.yarns; ++i)
    append_legacy_yarn(weft, p, {0, 0, 1}, {1, 0, 0}, first + i * S, (i % 2) ? 1.0 : -1.0);
  return {std::move(warp), std::move(weft)};
}

namespace {
detail::GltfDocument legacy_document(const WeaveParams& p) {
  const auto meshes = make_weave(p);
  const nlohmann::json extras = {
      {"pattern", p.pattern},
      {"yarns", p.yarns},
      {"yarn_radius_mm", p.yarn_radius_mm},
      {"spacing_mm", p.spacing_mm},
      {"segments", p.segments},
      {"sides", p.sides},
      {"amplitude_mm", p.amplitude_mm < 0 ? p.yarn_radius_mm : p.amplitude_mm},
      {"units", "metres"}};
  return detail::build_gltf(&meshes, nullptr, extras, {});
}
}  // namespace

std::string weave_to_gltf(const WeaveParams& p) {
  return detail::gltf_text(legacy_document(p));
}
std::vector<uint8_t> weave_to_glb(const WeaveParams& p) {
  return detail::glb_bytes(legacy_document(p));
}
void write_weave(const std::filesystem::path& path, const WeaveParams& params) {
  const auto ext = path.extension().string();
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path.string(), "", "output must end in .gltf or .glb");
  detail::write_gltf(path, legacy_document(params));
}

}  // namespace weft
