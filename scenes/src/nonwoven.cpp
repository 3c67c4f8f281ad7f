// The nonwoven generator (nonwoven.h): options checked, straight fibers placed one by one at a
// free height, cut at the tile's sides into the woven sample's wrap convention.
#include "weft/scenes/nonwoven.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string_view>

#include "weave_internal.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/core/rng.h"
#include "weft/scenes/weave.h"

namespace weft {
namespace {

using detail::kMetresPerMm;

// The bundled acrylic felt (scenes/examples/acrylic-felt.json; numbers in
// scenes/examples/README.md): the defaults of unset options.
constexpr double kFeltGsm = 170, kFeltThicknessMm = 1.2, kFeltInclinationSdDeg = 15;
constexpr double kFeltFiberLengthMm = 0.4, kFeltTileMm = 1.2, kFeltFiberRadiusUm = 9.5;
constexpr double kFeltDensityGcm3 = 1.17;
constexpr uint64_t kFeltSeed = 1;

constexpr double kMargin = 0.02;  // clearance 2 r (1 + margin), as at woven fiber detail
constexpr double kMaxInclinationDeg = 80;
constexpr double kMaxFibers = 20000;  // each placement looks at every fiber placed before
constexpr int kMaxTriesPerFiber = 2000;

[[noreturn]] void bad(const std::string& field, const std::string& msg) {
  throw Error("", field, msg);
}

double in_range(const std::optional<double>& v, double fallback, const std::string& field,
                double lo, double hi, bool lo_open = true) {
  const double x = v.value_or(fallback);
  if (!(std::isfinite(x) && (lo_open ? x > lo : x >= lo) && x <= hi))
    bad(field, std::string("must be finite and in ") + (lo_open ? "(" : "[") +
                   ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) + "], got " +
                   ParamReader::fmt(x));
  return x;
}

struct Mat {
  double gsm = 0, tile = 0, thickness = 0, radius = 0, length = 0, density = 0;  // mm, g/cm3
  double inclination_sd_deg = 0, inclination_sd = 0;                             // degrees, radians
  uint64_t seed = 0;
  int fibers = 0;
};

// The woven sample's options have no meaning for a mat.
void check_no_woven_options(const WeaveOptions& o) {
  const std::pair<bool, const char*> given[] = {
      {o.wif.has_value(), "wif"},
      {o.repeats_x.has_value() || o.repeats_z.has_value(), "repeats"},
      {o.warp_spacing_mm.has_value(), "warp-spacing-mm"},
      {o.weft_spacing_mm.has_value(), "weft-spacing-mm"},
      {o.warp_width_mm.has_value(), "warp-width-mm"},
      {o.weft_width_mm.has_value(), "weft-width-mm"},
      {o.warp_thickness_mm.has_value(), "warp-thickness-mm"},
      {o.weft_thickness_mm.has_value(), "weft-thickness-mm"},
      {o.warp_crimp_share.has_value(), "warp-crimp-share"},
      {o.segments_per_crossing.has_value(), "segments-per-crossing"},
      {o.sides.has_value(), "sides"},
      {o.fibers_per_yarn.has_value(), "fibers-per-yarn"},
      {o.packing.has_value(), "packing"},
      {o.plies.has_value(), "plies"},
      {o.twist_per_mm.has_value(), "twist-per-mm"},
      {o.twist_angle_deg.has_value(), "twist-angle-deg"},
      {o.ply_twist_per_mm.has_value(), "ply-twist-per-mm"}};
  for (const auto& [set, field] : given)
    if (set) bad(field, "does not apply to a nonwoven mat (--pattern nonwoven)");
  if (o.detail && *o.detail != "fiber")
    bad("detail", "a nonwoven mat has fiber detail only, got '" + *o.detail + "'");
}

// The options checked, the thickness from the solidity where that is given, and the fiber count
// estimated (and bounded) before anything is allocated.
Mat resolve_mat(const WeaveOptions& o) {
  check_no_woven_options(o);
  if (o.thickness_mm && o.solidity) bad("solidity", "give either thickness-mm or solidity");
  Mat m;
  m.gsm = in_range(o.areal_density_gsm, kFeltGsm, "areal-density-gsm", 0, 2000);
  m.density =
      in_range(o.fiber_density_g_cm3, kFeltDensityGcm3, "fiber-density-g-cm3", 0.5, 25, false);
  m.radius =
      in_range(o.fiber_radius_um, kFeltFiberRadiusUm, "fiber-radius-um", 0.5, 500, false) * 1e-3;
  m.tile = in_range(o.tile_mm, kFeltTileMm, "tile-mm", 0, 20);
  m.length = in_range(o.fiber_length_mm, kFeltFiberLengthMm, "fiber-length-mm", 4 * m.radius,
                      0.5 * m.tile, false);
  m.inclination_sd_deg =
      in_range(o.inclination_sd_deg, kFeltInclinationSdDeg, "inclination-sd-deg", 0, 45, false);
  m.inclination_sd = deg_to_rad(m.inclination_sd_deg);
  m.seed = o.seed.value_or(kFeltSeed);
  // Areal density g/m^2 over density g/cm^3 is a thickness in um: gsm / rho x 1e-3 mm.
  const double solid_mm = m.gsm / m.density * 1e-3;
  if (o.solidity) {
    const double phi = in_range(o.solidity, 0, "solidity", 0, 0.5);
    m.thickness = solid_mm / phi;
  } else {
    m.thickness = in_range(o.thickness_mm, kFeltThicknessMm, "thickness-mm", 0, 20);
    if (solid_mm / m.thickness > 0.5)
      bad("thickness-mm", "gives a solidity of " + ParamReader::fmt(solid_mm / m.thickness) +
                              " (fiber volume / mat volume), above 0.5: a thicker or lighter mat");
  }
  const std::string field = o.solidity ? "solidity" : "thickness-mm";
  if (m.thickness > 20)
    bad(field, "gives a mat " + ParamReader::fmt(m.thickness) + " mm thick, above 20 mm");
  if (m.thickness < 2 * m.radius * (1 + kMargin) * 2)
    bad(field,
        "the mat (" + ParamReader::fmt(m.thickness) + " mm) must be at least two fibers thick");
  // Fiber length in the tile: the fiber volume over the fiber's section.
  const double total_mm = solid_mm * m.tile * m.tile / (kPi * m.radius * m.radius);
  const double n = std::round(total_mm / m.length);
  if (n > kMaxFibers)
    bad("areal-density-gsm", "the mat would have " + ParamReader::fmt(n) +
                                 " fibers (limit 20000): a smaller tile, a lighter mat or "
                                 "longer fibers");
  if (n < 1)
    bad("areal-density-gsm", "the tile would hold no whole fiber: a larger tile or a heavier mat");
  m.fibers = static_cast<int>(n);
  return m;
}

struct Fiber {
  Vec3 a, b;  // ends (mm), the centre inside the tile
};

// A direction: in-plane angle uniform, inclination normal (sd), redrawn beyond 80 degrees or
// where a fiber of the mat's length would not fit its thickness.
Vec3 draw_direction(const Mat& m, Rng& rng) {
  const double room = m.thickness - 2 * m.radius * (1 + kMargin);
  double theta = 0;
  for (;;) {
    const double u1 = rng.uniform_open0(), u2 = rng.uniform();
    theta = m.inclination_sd * std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
    if (std::abs(theta) <= deg_to_rad(kMaxInclinationDeg) &&
        m.length * std::abs(std::sin(theta)) <= room)
      break;
  }
  const double phi = kPi * rng.uniform();
  return {std::cos(theta) * std::cos(phi), std::sin(theta), std::cos(theta) * std::sin(phi)};
}

// The heights y in [lo, hi] where the candidate a-b raised by y comes closer than 'clear' to the
// segment p-q: an interval (the distance is convex in y), empty when lo > hi on return.
std::pair<double, double> forbidden(const Vec3& a, const Vec3& b, const Vec3& p, const Vec3& q,
                                    double clear, double lo, double hi) {
  const Vec3 up{0, 1, 0};
  auto f = [&](double y) { return detail::segment_distance(a + up * y, b + up * y, p, q); };
  // Golden-section search for the minimum, to 1e-9 of the range.
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double l = lo, h = hi, m1 = h - g * (h - l), m2 = l + g * (h - l), f1 = f(m1), f2 = f(m2);
  for (int it = 0; it < 45; ++it) {
    if (f1 < f2)
      h = m2, m2 = m1, f2 = f1, m1 = h - g * (h - l), f1 = f(m1);
    else
      l = m1, m1 = m2, f1 = f2, m2 = l + g * (h - l), f2 = f(m2);
  }
  const double ymin = 0.5 * (l + h);
  if (f(ymin) >= clear) return {1, 0};
  auto edge = [&](double inside, double outside) {
    if (f(outside) < clear) return outside;
    for (int it = 0; it < 32; ++it) {
      const double mid = 0.5 * (inside + outside);
      (f(mid) < clear ? inside : outside) = mid;
    }
    return outside;
  };
  return {edge(ymin, lo), edge(ymin, hi)};
}

// A height for the candidate (centre c, direction d) drawn uniformly from those free of every
// placed fiber (nearest periodic copies), or none.
std::optional<double> free_height(const Mat& m, const std::vector<Fiber>& placed, const Vec3& c,
                                  const Vec3& d, Rng& rng) {
  const double clear = 2 * m.radius * (1 + kMargin);
  const double half_rise = 0.5 * m.length * std::abs(d.y);
  const double lo = -0.5 * m.thickness + 0.5 * clear + half_rise,
               hi = 0.5 * m.thickness - 0.5 * clear - half_rise;
  const Vec3 a = c - d * (0.5 * m.length), b = c + d * (0.5 * m.length);
  std::vector<std::pair<double, double>> blocked;
  auto flat = [](const Vec3& v) { return Vec3{v.x, 0, v.z}; };
  // Every periodic copy whose centre lies within reach (a fiber and the candidate, each up to
  // half the tile long, can meet through more than one copy).
  const double reach = m.length + clear;
  for (const Fiber& f : placed)
    for (int i = -1; i <= 1; ++i)
      for (int k = -1; k <= 1; ++k) {
        const Vec3 shift{i * m.tile, 0, k * m.tile};
        const Vec3 fc = 0.5 * (f.a + f.b) + shift;
        if (std::abs(fc.x - c.x) > reach || std::abs(fc.z - c.z) > reach) continue;
        const Vec3 p = f.a + shift, q = f.b + shift;
        // Seen from above the two must come within 'clear' for any height to be blocked.
        if (detail::segment_distance(flat(a), flat(b), flat(p), flat(q)) >= clear) continue;
        // Heights where their vertical ranges come within 'clear'.
        const double ylo = std::max(lo, std::min(p.y, q.y) - std::max(a.y, b.y) - clear);
        const double yhi = std::min(hi, std::max(p.y, q.y) - std::min(a.y, b.y) + clear);
        if (ylo > yhi) continue;
        const auto iv = forbidden(a, b, p, q, clear, ylo, yhi);
        if (iv.first <= iv.second) blocked.push_back(iv);
      }
  std::sort(blocked.begin(), blocked.end());
  std::vector<std::pair<double, double>> gaps;  // free heights
  double from = lo, total = 0;
  for (const auto& [b0, b1] : blocked) {
    if (b0 > from) gaps.push_back({from, b0}), total += b0 - from;
    from = std::max(from, b1);
  }
  if (hi > from) gaps.push_back({from, hi}), total += hi - from;
  if (!(total > 1e-9 * m.thickness)) return std::nullopt;
  double u = rng.uniform() * total;
  for (const auto& [g0, g1] : gaps) {
    if (u <= g1 - g0) return g0 + u;
    u -= g1 - g0;
  }
  return gaps.back().second;
}

// Each placement looks at every fiber placed before, so the largest mat (20 000 fibers) takes tens
// of seconds: 'keep_going' (fibers placed, fibers in all) is asked before every placement drawn,
// at most a few milliseconds apart. When it says stop, the fibers placed so far are returned.
std::vector<Fiber> place_fibers(const Mat& m, const std::string& thickness_field, int& attempts,
                                const std::function<bool(uint64_t, uint64_t)>& keep_going) {
  std::vector<Fiber> placed;
  placed.reserve(m.fibers);
  Rng rng(m.seed, 0x6e6f6e776f76656eULL);  // "nonwoven"
  attempts = 0;
  while (static_cast<int>(placed.size()) < m.fibers) {
    int tries = 0;
    for (;; ++tries) {
      if (!keep_going(placed.size(), uint64_t(m.fibers))) return placed;
      if (tries == kMaxTriesPerFiber)
        bad(thickness_field,
            "the mat does not fit: no free place for fiber " + std::to_string(placed.size() + 1) +
                " of " + std::to_string(m.fibers) + " in " + std::to_string(kMaxTriesPerFiber) +
                " tries; a thicker or lighter mat, or shorter fibers");
      ++attempts;
      const Vec3 d = draw_direction(m, rng);
      Vec3 c{m.tile * (rng.uniform() - 0.5), 0, m.tile * (rng.uniform() - 0.5)};
      const auto y = free_height(m, placed, c, d, rng);
      if (!y) continue;
      c.y = *y;
      placed.push_back({c - d * (0.5 * m.length), c + d * (0.5 * m.length)});
      break;
    }
  }
  return placed;
}

// Each fiber cut where it crosses the tile's sides, every piece moved by whole tiles into the
// tile: a curve each, all pieces of fiber k in "yarn" k (so that the measurement finds where a
// fiber continues).
FiberCurves cut_into_tile(const Mat& m, const std::vector<Fiber>& fibers) {
  FiberCurves out;
  const float radius_m = static_cast<float>(m.radius * kMetresPerMm);
  const double P = m.tile;
  for (size_t k = 0; k < fibers.size(); ++k) {
    const Vec3 a = fibers[k].a, e = fibers[k].b - fibers[k].a;
    std::vector<double> cuts = {0, 1};
    for (const int axis : {0, 2})
      if (e[axis] != 0)
        for (double side = -1.5 * P; side <= 1.5 * P; side += P) {
          const double t = (side - a[axis]) / e[axis];
          if (t > 0 && t < 1) cuts.push_back(t);
        }
    std::sort(cuts.begin(), cuts.end());
    out.yarn_material.push_back("warp");  // one material for every fiber (docs/weave.md)
    for (size_t i = 0; i + 1 < cuts.size(); ++i) {
      if ((cuts[i + 1] - cuts[i]) * m.length < 1e-6 * m.radius) continue;  // a corner's sliver
      const Vec3 mid = a + e * (0.5 * (cuts[i] + cuts[i + 1]));
      const Vec3 shift{-P * std::floor((mid.x + 0.5 * P) / P), 0,
                       -P * std::floor((mid.z + 0.5 * P) / P)};
      out.curve_first.push_back(static_cast<uint32_t>(out.point_count()));
      out.curve_points.push_back(2);
      out.curve_yarn.push_back(static_cast<uint32_t>(k));
      for (const double t : {cuts[i], cuts[i + 1]}) {
        const Vec3 p = (a + e * t + shift) * kMetresPerMm;
        out.points.insert(out.points.end(), {static_cast<float>(p.x), static_cast<float>(p.y),
                                             static_cast<float>(p.z), radius_m});
      }
    }
  }
  out.names = {"patch"};
  return out;
}

// The counts and the measured closest approach; the mat refused when fibers interpenetrate.
// 'keep_going' is asked between slices of the distance search (min_fiber_distance); when it says
// stop, the measurement is left unfinished and unchecked.
void summarise(const Mat& m, int attempts, WovenSample& s,
               const std::function<bool(uint64_t, uint64_t)>& keep_going) {
  WeaveSummary& w = s.summary;
  const FiberCurves& f = s.fibers;
  w.source = kNonwovenPattern;
  w.detail = "fiber";
  w.repeat_x_mm = w.repeat_z_mm = w.period_x_mm = w.period_z_mm = m.tile;
  w.curves = f.curve_count();
  w.curve_points = f.point_count();
  w.curve_segments = f.segment_count();
  double length_m = 0, ylo = 1e300, yhi = -1e300;
  for (size_t c = 0; c < f.curve_count(); ++c)
    length_m += length(f.point(f.curve_first[c] + 1) - f.point(f.curve_first[c]));
  for (size_t i = 0; i < f.point_count(); ++i) {
    ylo = std::min(ylo, f.point(i).y - f.radius(i));
    yhi = std::max(yhi, f.point(i).y + f.radius(i));
  }
  w.y_min_mm = ylo / kMetresPerMm;
  w.y_max_mm = yhi / kMetresPerMm;
  const double r_m = m.radius * kMetresPerMm, tile_m = m.tile * kMetresPerMm;
  const double volume_m3 = length_m * kPi * r_m * r_m;
  NonwovenSummary n;
  n.areal_density_gsm = volume_m3 * m.density * 1e6 / (tile_m * tile_m);  // g/cm3 -> g/m3
  n.thickness_mm = m.thickness;
  n.solidity = volume_m3 / (tile_m * tile_m * m.thickness * kMetresPerMm);
  n.fiber_length_mm = m.length;
  n.fiber_density_g_cm3 = m.density;
  n.inclination_sd_deg = m.inclination_sd_deg;
  n.fibers = m.fibers;
  n.attempts = attempts;
  n.seed = m.seed;
  w.nonwoven = n;
  const double d = min_fiber_distance(f, tile_m, tile_m, 4 * r_m, keep_going);
  if (s.cancelled) return;
  w.min_fiber_distance_um = d * 1e6;
  if (d < 2 * r_m * (1 - 1e-2))
    bad("thickness-mm", "fibers would interpenetrate: closest centre lines " +
                            ParamReader::fmt(d * 1e6) + " um apart");
}

}  // namespace

WovenSample make_nonwoven_sample(const WeaveOptions& options, const ProgressCallback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const Mat m = resolve_mat(options);
  WovenSample s;
  auto asker = [&](std::string_view stage, std::string_view unit) {
    return detail::sample_asker(s, progress, stage, unit);
  };
  int attempts = 0;
  const std::vector<Fiber> fibers = place_fibers(m, options.solidity ? "solidity" : "thickness-mm",
                                                 attempts, asker("nonwoven sample", "fibers"));
  if (s.cancelled) return s;
  s.fibers = cut_into_tile(m, fibers);
  summarise(m, attempts, s, asker("fiber distances", "cells"));
  if (s.cancelled) return s;
  s.summary.seconds = seconds_since(t0);
  return s;
}

namespace {

// The tries expected to place the mat and the fibers they look at (NonwovenSize). When k of
// the n fibers are placed, a candidate crosses, seen from above, the fibers whose centres lie in
// the area (2 / pi) L^2 + 4 c L + pi c^2 around its own (two segments of length L at a uniform
// angle, within the clearance c): on average m_k = k A / P^2 of them, each blocking a height
// interval of about 1.33 x 2c of the column's free range H (the thickness less c and the mean
// rise L |sin theta|). Taken as placed independently, the m_k intervals cover the whole range with
// probability exp(-m_k exp(-m_k h / H)) (each interval leaves a gap past its end unless another
// covers it), and a placement takes 1 / (1 - that) tries. The 1.33 is fitted: with it, the tries
// counted on the bundled felt at thicknesses 1.0-2.4 mm and tiles 1.2-3.4 mm (1.0-15.4 tries a
// fiber, 2026-12-06) come within 0.73-1.10 of these.
void expect_placement_work(const Mat& m, NonwovenSize& z) {
  constexpr double kBlockedPerClearance = 1.33;
  constexpr int kSteps = 256;
  const double clear = 2 * m.radius * (1 + kMargin);
  const double area = (2 / kPi) * m.length * m.length + 4 * clear * m.length + kPi * clear * clear;
  const double crossing = m.fibers * area / (m.tile * m.tile);
  const double mean_rise = m.length * std::sin(m.inclination_sd) * std::sqrt(2 / kPi);
  const double range = std::max(m.thickness - clear - mean_rise, clear);
  const double blocked = kBlockedPerClearance * 2 * clear;
  for (int i = 0; i < kSteps; ++i) {
    const double k = (i + 0.5) / kSteps;
    const double mk = k * crossing;
    const double covered = std::exp(-mk * std::exp(-mk * blocked / range));
    const double tries = std::min(1 / std::max(1 - covered, 1e-12), double(kMaxTriesPerFiber));
    const double fibers_here = double(m.fibers) / kSteps;
    z.placement_tries += tries * fibers_here;
    z.crossing_checks += tries * fibers_here * mk;
    z.copy_checks += tries * fibers_here * 9 * k * m.fibers;
  }
}

}  // namespace

NonwovenSize nonwoven_sample_size(const WeaveOptions& options) {
  const Mat m = resolve_mat(options);
  // A fiber is cut once where it crosses a side of the tile (its length is at most half the
  // tile's). With its centre uniform in the tile, it crosses the sides across x with probability
  // (its extent along x) / P: L cos(theta) |cos(phi)| / P, whose mean over the uniform in-plane
  // angle is (2 / pi) L cos(theta) / P, and as much across z. The inclination's cosine is taken at
  // its mean under the normal law, exp(-sd^2 / 2) (the redraws beyond 80 degrees ignored).
  const double cos_theta = std::exp(-0.5 * m.inclination_sd * m.inclination_sd);
  const double pieces = 1 + 2 * (2 / kPi) * m.length * cos_theta / m.tile;
  NonwovenSize z;
  z.fibers = m.fibers;
  z.curves = std::round(m.fibers * pieces);
  expect_placement_work(m, z);
  return z;
}

}  // namespace weft
