// Fiber detail of the weave generator: fibers on nested rings inside each yarn's lens section
// (or inside ply discs carried around the yarn), carried around the rings by the twist; and the
// measurement of the closest approach of distinct fibers on a uniform grid.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>

#include "weave_internal.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/scenes/description.h"

namespace weft::detail {
namespace {

// Spacing margin over 2 x radius: covers the polyline's chords and second-order effects of the
// tilt that the first-order spacing below leaves out; the final measurement checks the result.
constexpr double kMargin = 0.02;
constexpr int kLensVertices = 128;

struct V2 {
  double x = 0, y = 0;  // x: lateral offset l, y: height offset (mm), in the yarn's section
};
V2 operator+(V2 a, V2 b) {
  return {a.x + b.x, a.y + b.y};
}
V2 operator-(V2 a, V2 b) {
  return {a.x - b.x, a.y - b.y};
}
V2 operator*(V2 a, double s) {
  return {a.x * s, a.y * s};
}
double dot2(V2 a, V2 b) {
  return a.x * b.x + a.y * b.y;
}
double len2(V2 a) {
  return std::sqrt(dot2(a, a));
}
using Poly = std::vector<V2>;  // convex, counter-clockwise

double area(const Poly& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const V2 &u = p[i], &v = p[(i + 1) % p.size()];
    a += u.x * v.y - v.x * u.y;
  }
  return 0.5 * a;
}

// The lens polygon: vertices on the lens boundary (so inside the convex lens), tips included.
Poly lens_polygon(double w, double t) {
  Poly p;
  for (int k = 0; k < kLensVertices; ++k) {
    const double phi = 2 * kPi * k / kLensVertices;
    const double c = std::cos(phi), s = std::sin(phi);
    const double sg = s > 1e-12 ? 1 : (s < -1e-12 ? -1 : 0);
    p.push_back({0.5 * w * c, 0.5 * t * sg * std::cos(0.5 * kPi * c)});
  }
  return p;
}

// Keeps the part of 'poly' where dot(n, p) >= c (Sutherland-Hodgman for one half-plane).
Poly clip(const Poly& poly, V2 n, double c) {
  Poly out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const V2 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = dot2(n, a) - c, db = dot2(n, b) - c;
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

// The base polygon eroded by delta: the intersection of its edges' half-planes moved inwards.
Poly erode(const Poly& base, double delta) {
  Poly out = base;
  for (size_t i = 0; i < base.size() && !out.empty(); ++i) {
    const V2 e = base[(i + 1) % base.size()] - base[i];
    const double l = len2(e);
    if (l <= 0) continue;
    const V2 n{-e.y / l, e.x / l};  // inward (left) normal of a counter-clockwise polygon
    out = clip(out, n, dot2(n, base[i]) + delta);
  }
  return out;
}

// A closed curve parametrised by arc length.
struct Ring {
  std::vector<V2> pts;
  std::vector<double> cum;  // arc length at each point; cum.back() = perimeter (closing edge)
  double per = 0;
  V2 at(double sigma) const {
    if (pts.size() == 1 || per <= 0) return pts[0];
    double r = sigma - per * std::floor(sigma / per);
    const size_t i = std::min<size_t>(
        pts.size() - 1,
        static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), r) - cum.begin()) - 1);
    const V2 a = pts[i], b = pts[(i + 1) % pts.size()];
    const double seg = cum[i + 1] - cum[i];
    return seg > 0 ? a + (b - a) * ((r - cum[i]) / seg) : a;
  }
};

Ring make_ring(std::vector<V2> pts) {
  Ring r;
  // Drop repeated points.
  for (const V2& p : pts)
    if (r.pts.empty() || len2(p - r.pts.back()) > 1e-12) r.pts.push_back(p);
  while (r.pts.size() > 1 && len2(r.pts.front() - r.pts.back()) <= 1e-12) r.pts.pop_back();
  r.cum.push_back(0);
  for (size_t i = 0; i < r.pts.size(); ++i)
    r.cum.push_back(r.cum.back() +
                    (r.pts.size() > 1 ? len2(r.pts[(i + 1) % r.pts.size()] - r.pts[i]) : 0));
  r.per = r.cum.back();
  return r;
}

// Boundary of (E dilated by rho): E's edges moved out by rho, joined by arcs at its vertices.
Ring rounded(const Poly& e, double rho) {
  if (rho <= 0) return make_ring(e);
  std::vector<V2> pts;
  const size_t n = e.size();
  for (size_t i = 0; i < n; ++i) {
    const V2 prev = e[i] - e[(i + n - 1) % n], next = e[(i + 1) % n] - e[i];
    const double a0 = std::atan2(-prev.x, prev.y);  // outward normal of the incoming edge
    double a1 = std::atan2(-next.x, next.y);
    while (a1 < a0) a1 += 2 * kPi;
    const int steps = std::max(1, static_cast<int>(std::ceil((a1 - a0) / (kPi / 18))));
    for (int k = 0; k <= steps; ++k) {
      const double a = a0 + (a1 - a0) * k / steps;
      pts.push_back({e[i].x + rho * std::cos(a), e[i].y + rho * std::sin(a)});
    }
  }
  return make_ring(pts);
}

// The ring at inset 'delta' of the section 'base' (boundary of the erosion by delta + rho dilated
// by rho, rho as large as allowed up to rho_max), or a single point when only a sliver is left,
// or nothing. Successive insets 'd' apart give rings at least d apart as long as rho <= d.
std::optional<Ring> inset_ring(const Poly& base, double delta, double rho_max, double min_area) {
  for (double rho : {rho_max, 0.5 * rho_max, 0.25 * rho_max, 0.0}) {
    const Poly e = erode(base, delta + rho);
    if (e.size() >= 3 && area(e) > min_area) return rounded(e, rho);
  }
  const Poly e = erode(base, delta);
  if (e.empty()) return std::nullopt;
  V2 c;
  for (const V2& p : e) c = c + p;
  return make_ring({c * (1.0 / e.size())});
}

// Smallest distance between any two of n points evenly spaced on the ring, over phases.
double min_pair_distance(const Ring& r, int n) {
  if (n < 2) return 1e300;
  double best = 1e300;
  std::vector<V2> p(n);
  constexpr int kPhases = 16;
  for (int ph = 0; ph < kPhases; ++ph) {
    for (int i = 0; i < n; ++i) p[i] = r.at(r.per * (i + double(ph) / kPhases) / n);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) best = std::min(best, len2(p[i] - p[j]));
  }
  return best;
}

// Twist rounded so that the n fibers of a ring map onto each other after one period.
double periodic_rate(double rate, double period, int n) {
  return std::round(rate * period * n) / (period * n);
}

struct FiberRing {
  Ring ring;
  int n = 0;
  double rate = 0;   // turns per mm (signed: > 0 is Z twist)
  double phase = 0;  // fraction of the fiber spacing
  // The core: fibers in a straight row from 'ring.pts[0]' to 'ring.pts[1]', not carried round
  // (the axis of a twisted yarn does not turn). Used where the section left inside the last ring
  // is too thin for a ring whose two sides stay 2 radii apart; there a row holds more fibers.
  bool row = false;
};

// Rings of fibers in a convex section: nested insets 'ring_gap' apart starting at 'inset', each
// with as many fibers as keep 'chord(u)' apart where u is the fibers' in-section speed; the
// innermost level may be a core row instead (whichever holds more fibers in all).
struct RingPlan {
  std::vector<FiberRing> rings;
  std::vector<int> capacity;
  int total = 0;
};

struct Requirements {
  double two_r = 0;   // 2 x radius x (1 + margin)
  double slope = 0;   // vertical sections: largest crimp slope of the yarn; perpendicular: 0
  double rate = 0;    // fiber turns per mm about the section's own axis
  double carry = 0;   // in-section speed added by a carrying motion (ply twist), mm per mm
  double period = 0;  // along the yarn
};

// The chord of the convex polygon 'e' along x through its centroid's height, as a row ring.
std::optional<FiberRing> core_row(const Poly& e) {
  if (e.size() < 3) return std::nullopt;
  double yc = 0;
  for (const V2& p : e) yc += p.y;
  yc /= static_cast<double>(e.size());
  double x0 = 1e300, x1 = -1e300;
  for (size_t i = 0; i < e.size(); ++i) {
    const V2 &a = e[i], &b = e[(i + 1) % e.size()];
    if ((a.y - yc) * (b.y - yc) > 0) continue;
    const double x = a.y == b.y ? a.x : a.x + (b.x - a.x) * (yc - a.y) / (b.y - a.y);
    x0 = std::min({x0, x, a.y == b.y ? b.x : x});
    x1 = std::max({x1, x, a.y == b.y ? b.x : x});
  }
  if (!(x1 >= x0)) return std::nullopt;
  FiberRing fr;
  fr.row = true;
  fr.ring.pts = {{x0, yc}, {x1, yc}};
  fr.ring.per = x1 - x0;  // the row's length
  return fr;
}

int row_capacity(const FiberRing& fr, double spacing) {
  return static_cast<int>(std::floor(fr.ring.per / spacing)) + 1;
}

RingPlan plan_rings(const Poly& section, double inset, const Requirements& q, double lambda,
                    double min_area) {
  const double gap = lambda * q.two_r * std::sqrt(1 + q.slope * q.slope);
  std::vector<FiberRing> rings, rows;
  std::vector<int> ring_cap, row_cap;
  for (int k = 0; k < 64; ++k) {
    const auto ring = inset_ring(section, inset + k * gap, gap, min_area);
    if (!ring) break;
    // Every point of the section eroded by this level's inset lies a gap inside the previous
    // ring, so a row there keeps clear of it.
    const auto row = core_row(erode(section, inset + k * gap));
    rows.push_back(row.value_or(FiberRing{}));
    row_cap.push_back(row ? row_capacity(*row, gap) : 0);
    FiberRing fr;
    fr.ring = *ring;
    int best = 1;
    if (fr.ring.per > 0) {
      const int guess = static_cast<int>(fr.ring.per / (lambda * q.two_r)) + 1;
      for (int n = guess; n >= 2; --n) {
        const double rate = periodic_rate(q.rate, q.period, n);
        const double u = std::abs(rate) * fr.ring.per + q.carry + q.slope;
        if (min_pair_distance(fr.ring, n) >= lambda * q.two_r * std::sqrt(1 + u * u)) {
          best = n;
          break;
        }
      }
    }
    ring_cap.push_back(best);
    rings.push_back(std::move(fr));
  }
  // The innermost level 'cut' is a row (cut < levels) or every level is a ring (cut = levels).
  const size_t levels = rings.size();
  size_t best_cut = levels;
  int best_total = 0, sum = 0;
  for (int c : ring_cap) best_total += c;
  for (size_t cut = 0; cut < levels; ++cut) {
    if (row_cap[cut] > 0 && sum + row_cap[cut] > best_total)
      best_total = sum + row_cap[cut], best_cut = cut;
    sum += ring_cap[cut];
  }
  RingPlan plan;
  for (size_t k = 0; k < std::min(best_cut + 1, levels); ++k) {
    const bool row = k == best_cut;
    plan.rings.push_back(row ? rows[k] : rings[k]);
    plan.capacity.push_back(row ? row_cap[k] : ring_cap[k]);
  }
  plan.total = best_total;
  return plan;
}

bool ring_ok(const FiberRing& fr, int n, const Requirements& q, double lambda) {
  if (n <= 1 || fr.row) return true;  // fewer fibers on a row lie further apart
  const double rate = periodic_rate(q.rate, q.period, n);
  const double u = std::abs(rate) * fr.ring.per + q.carry + q.slope;
  return min_pair_distance(fr.ring, n) >= lambda * q.two_r * std::sqrt(1 + u * u);
}

// The spacing factor lambda >= 1 is raised as far as 'count' fibers still fit, so that fewer
// fibers spread over the section instead of crowding its rim; then rings give up fibers until
// exactly 'count' remain.
std::vector<FiberRing> fit_rings(const Poly& section, double inset, const Requirements& q,
                                 int count, double min_area, int* capacity_at_1) {
  RingPlan best = plan_rings(section, inset, q, 1.0, min_area);
  *capacity_at_1 = best.total;

  if (best.total < count) return {};
  double lo = 1, hi = 4;
  for (int it = 0; it < 20; ++it) {
    const double mid = 0.5 * (lo + hi);
    RingPlan p = plan_rings(section, inset, q, mid, min_area);
    if (p.total >= count) {
      lo = mid;
      best = std::move(p);
    } else {
      hi = mid;
    }
  }
  std::vector<int> n = best.capacity;
  int excess = best.total - count;
  while (excess > 0) {
    int pick = -1;
    double densest = -1;
    for (size_t k = 0; k < n.size(); ++k) {
      if (n[k] == 0 || !(n[k] == 1 || ring_ok(best.rings[k], n[k] - 1, q, lo))) continue;
      const double d = n[k] / std::max(best.rings[k].ring.per, 1e-9);
      if (d > densest) densest = d, pick = static_cast<int>(k);
    }
    if (pick < 0) break;  // cannot happen: a ring can always drop to zero
    --n[pick];
    --excess;
  }
  std::vector<FiberRing> out;
  for (size_t k = 0; k < n.size(); ++k) {
    if (n[k] == 0) continue;
    FiberRing fr = best.rings[k];
    fr.n = n[k];
    fr.rate = fr.row ? 0 : periodic_rate(q.rate, q.period, fr.n);
    fr.phase = 0.5 * (k % 2);  // alternate rings start half a spacing apart
    out.push_back(std::move(fr));
  }
  return out;
}

Poly circle_polygon(double radius) {
  Poly p;
  for (int k = 0; k < kLensVertices; ++k) {
    const double a = 2 * kPi * k / kLensVertices;
    p.push_back({radius * std::cos(a), radius * std::sin(a)});
  }
  return p;
}

// The fibers of one yarn section: where fiber f sits in the section at along coordinate s.
struct Bundle {
  std::vector<FiberRing> rings;  // single ply: in the section; plies: in a ply, about its centre
  int plies = 1;
  Ring ply_ring;
  double ply_rate = 0;
  int fibers = 0;  // in the whole section
  FiberLayoutInfo info;

  V2 offset(int f, double s) const {
    const int per_ply = fibers / plies;
    const int ply = f / per_ply;
    int i = f % per_ply;
    size_t k = 0;
    while (i >= rings[k].n) i -= rings[k++].n;
    const FiberRing& fr = rings[k];
    V2 p;
    if (fr.row) {
      p = fr.n == 1 ? (fr.ring.pts[0] + fr.ring.pts[1]) * 0.5
                    : fr.ring.pts[0] + (fr.ring.pts[1] - fr.ring.pts[0]) * (double(i) / (fr.n - 1));
    } else {
      // Z twist (rate > 0) turns right-handedly about the yarn's direction: clockwise in (l, y).
      const double sigma = fr.ring.per * ((i + fr.phase) / fr.n - fr.rate * s);
      p = fr.ring.at(sigma);
    }
    if (plies > 1) {
      const double ps = ply_ring.per * (double(ply) / plies - ply_rate * s);
      p = p + ply_ring.at(ps);
    }
    return p;
  }
};

Bundle make_bundle(double w, double t, double slope, double period, const FiberSettings& fs,
                   const std::string& dir) {
  Bundle b;
  b.plies = fs.plies;
  const double r = fs.radius_mm;
  const double section_area = 2 * w * t / kPi;
  const int count =
      fs.fibers_per_yarn > 0
          ? fs.fibers_per_yarn
          : std::max(1, static_cast<int>(std::round(fs.packing * section_area / (kPi * r * r))));
  const std::string field = fs.fibers_per_yarn > 0 ? "fibers-per-yarn" : "packing";
  Requirements q;
  q.two_r = 2 * r * (1 + kMargin);
  // Vertical sections: fibers one above the other, both sloping, are closer than their
  // vertical distance by the cosine of the slope, so spacings grow by sqrt(1 + slope^2).
  q.slope = fs.perpendicular ? 0 : slope;
  q.period = period;
  const double inset = r * (1 + kMargin) * std::sqrt(1 + q.slope * q.slope);
  const Poly lens = lens_polygon(w, t);
  const double min_area = 1e-12 * w * t;
  auto twist_rate = [&](double outer_perimeter) {
    if (!fs.twist_from_angle) return fs.twist_per_mm;
    return std::tan(deg_to_rad(fs.twist_angle_deg)) / std::max(outer_perimeter, 1e-9);
  };
  int capacity = 0;
  // Fibers in 'section' (per ply); with neither packing nor count given, the most that fit where
  // the default packing's count does not.
  auto fill = [&](const Poly& section, int wanted) {
    b.rings = fit_rings(section, inset, q, wanted, min_area, &capacity);
    if (b.rings.empty() && fs.densest_if_needed && capacity >= 1) {
      b.info.default_packing = fs.packing;
      wanted = capacity;
      b.rings = fit_rings(section, inset, q, wanted, min_area, &capacity);
    }
    return wanted;
  };
  if (fs.plies == 1) {
    const auto outer = inset_ring(lens, inset, q.two_r, min_area);
    q.rate = twist_rate(outer ? outer->per : 0);
    b.fibers = fill(lens, count);
  } else {
    // Largest ply radius for which 'plies' discs on a ring inset by their radius never overlap.
    double lo = 0, hi = 0.5 * std::min(w, t);
    std::optional<Ring> best_ring;
    for (int it = 0; it < 30; ++it) {
      const double rp = 0.5 * (lo + hi);
      const auto ring = inset_ring(lens, rp, 0.5 * rp, min_area);
      if (ring && ring->per > 0 && min_pair_distance(*ring, fs.plies) >= 2 * rp) {
        lo = rp;
        best_ring = ring;
      } else {
        hi = rp;
      }
    }
    if (!best_ring || lo < r)
      throw Error("", "plies",
                  std::to_string(fs.plies) + " plies do not fit in a " + ParamReader::fmt(w) +
                      " x " + ParamReader::fmt(t) + " mm yarn section (" + dir + ")");
    b.ply_ring = *best_ring;
    b.ply_rate = periodic_rate(fs.ply_twist_per_mm, period, fs.plies);
    const int per_ply = std::max(1, static_cast<int>(std::round(double(count) / fs.plies)));
    const Poly disc = circle_polygon(lo);
    q.carry = std::abs(b.ply_rate) * b.ply_ring.per;
    q.rate = twist_rate(2 * kPi * std::max(lo - inset, 0.0));
    b.fibers = fill(disc, per_ply) * fs.plies;
    capacity *= fs.plies;
  }
  if (b.rings.empty())
    throw Error("", field,
                "at most " + std::to_string(capacity) + " fibers of radius " +
                    ParamReader::fmt(r * 1e3) + " um fit in a " + ParamReader::fmt(w) + " x " +
                    ParamReader::fmt(t) + " mm " + dir + " section (" + std::to_string(fs.plies) +
                    " ply) at this twist without touching; " + std::to_string(count) + " asked");
  b.info.fibers = b.fibers;
  b.info.packing = b.fibers * kPi * r * r / section_area;
  b.info.twist_per_mm = b.rings.front().rate;
  const double outer_circumference = b.rings.front().ring.per;
  b.info.twist_angle_deg = rad_to_deg(std::atan(b.info.twist_per_mm * outer_circumference));
  return b;
}

}  // namespace

void build_fibers(const Layout& layout, const FiberSettings& fs, FiberCurves& out,
                  std::vector<FiberLayoutInfo>& warp_info, std::vector<FiberLayoutInfo>& weft_info,
                  const std::function<bool(uint64_t, uint64_t)>& keep_going) {
  std::map<std::tuple<bool, double, double, double, double>, Bundle> bundles;
  const Vec3 up{0, 1, 0};
  const float radius_m = static_cast<float>(fs.radius_mm * kMetresPerMm);
  for (size_t yi = 0; yi < layout.yarns.size(); ++yi) {
    if (!keep_going(yi, layout.yarns.size())) return;
    const YarnPath& y = layout.yarns[yi];
    const auto key =
        std::make_tuple(y.warp, y.size.width_mm, y.size.thickness_mm, y.max_slope(), y.period);
    auto it = bundles.find(key);
    if (it == bundles.end()) {
      it = bundles
               .emplace(key, make_bundle(y.size.width_mm, y.size.thickness_mm, y.max_slope(),
                                         y.period, fs, y.warp ? "warp" : "weft"))
               .first;
      (y.warp ? warp_info : weft_info).push_back(it->second.info);
    }
    const Bundle& b = it->second;
    out.yarn_material.push_back(y.warp ? "warp" : "weft");
    const int K = static_cast<int>(y.crossing.size()) * layout.segments_per_crossing;
    for (int f = 0; f < b.fibers; ++f) {
      out.curve_first.push_back(static_cast<uint32_t>(out.point_count()));
      out.curve_points.push_back(static_cast<uint32_t>(K + 1));
      out.curve_yarn.push_back(static_cast<uint32_t>(yi));
      for (int k = 0; k <= K; ++k) {
        const double along = y.period * k / K;              // from the sample's start
        const double s = y.start + y.period * (k % K) / K;  // crimp: exactly periodic
        const V2 o = b.offset(f, along);
        // Perpendicular sections: the section's 'up' axis is the centre line's normal in the
        // vertical plane, so the fibers of a yarn are parallel curves (equal offsets keep equal
        // distances wherever the line slopes). Vertical sections: straight up, as the tubes.
        double slope = 0;
        const double h = y.height_at(s, &slope);
        const Vec3 normal =
            fs.perpendicular ? (up - y.along() * slope) * (1 / std::sqrt(1 + slope * slope)) : up;
        const Vec3 p = (y.along() * (y.start + along) + y.across() * y.centre + up * h +
                        normal * o.y + y.lateral() * o.x) *
                       kMetresPerMm;
        out.points.insert(out.points.end(), {static_cast<float>(p.x), static_cast<float>(p.y),
                                             static_cast<float>(p.z), radius_m});
      }
    }
  }
}

FiberCount count_fibers(const Layout& layout, const FiberSettings& fs) {
  std::map<std::tuple<bool, double, double, double, double>, int> fibers_of;  // as build_fibers
  FiberCount n;
  for (const YarnPath& y : layout.yarns) {
    const auto key =
        std::make_tuple(y.warp, y.size.width_mm, y.size.thickness_mm, y.max_slope(), y.period);
    auto it = fibers_of.find(key);
    if (it == fibers_of.end())
      it = fibers_of
               .emplace(key, make_bundle(y.size.width_mm, y.size.thickness_mm, y.max_slope(),
                                         y.period, fs, y.warp ? "warp" : "weft")
                                 .fibers)
               .first;
    const double K = double(y.crossing.size()) * layout.segments_per_crossing;
    n.curves += it->second;
    n.points += it->second * (K + 1);
  }
  return n;
}

}  // namespace weft::detail

namespace weft {
namespace detail {

// Closest points of segments p0-p1 and q0-q1 (Ericson, Real-Time Collision Detection, 5.1.9).
double segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (a <= 1e-30 && e <= 1e-30) return length(r);
  if (a <= 1e-30) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e <= 1e-30) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2), den = a * e - b * b;
      s = den > 0 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return length((p0 + d1 * s) - (q0 + d2 * t));
}

}  // namespace detail

using detail::segment_distance;

namespace {

struct Seg {
  Vec3 a, b, lo, hi;  // ends; box grown by cutoff / 2
  uint32_t curve;
  uint32_t index;  // within its curve
};

// For each curve, the curve that continues it across a side of the sample (-1: none): a fiber
// that leaves through a side continues as the curve of its yarn that starts where it ends, a
// period away.
std::vector<int64_t> continuations(const FiberCurves& fibers, double period_x, double period_z) {
  const double joined = 1e-9;  // float storage of points a period apart
  std::vector<int64_t> next(fibers.curve_count(), -1);
  std::map<uint32_t, std::vector<uint32_t>> by_yarn;
  for (size_t c = 0; c < fibers.curve_count(); ++c)
    by_yarn[fibers.curve_yarn[c]].push_back(static_cast<uint32_t>(c));
  for (const auto& [yarn, curves] : by_yarn)
    for (uint32_t c : curves) {
      const Vec3 end = fibers.point(fibers.curve_first[c] + fibers.curve_points[c] - 1);
      for (uint32_t c2 : curves) {
        Vec3 d = fibers.point(fibers.curve_first[c2]) - end;
        d.x -= period_x * std::round(d.x / period_x);
        d.z -= period_z * std::round(d.z / period_z);
        if (length(d) < joined) next[c] = c2;
      }
    }
  return next;
}

// A uniform grid, periodic in x and z, of cells at least 'size' wide; each segment lies in the one
// cell of its midpoint, so two segments whose midpoints (nearest periodic images) are less than
// 'size' apart along every axis lie in the same or neighbouring cells.
struct SegmentGrid {
  int n[3] = {1, 1, 1};
  double lo[3] = {0, 0, 0}, cell[3] = {1, 1, 1};
  std::vector<Seg> segs;             // sorted by cell
  std::vector<uint64_t> cell_start;  // cells + 1 offsets into 'segs'
  std::vector<uint64_t> keys;        // occupied cells, ascending

  int index(int axis, double v) const {
    const long i = std::lround(std::floor((v - lo[axis]) / cell[axis]));
    if (axis == 1) return static_cast<int>(std::clamp<long>(i, 0, n[1] - 1));
    return static_cast<int>(((i % n[axis]) + n[axis]) % n[axis]);
  }
  uint64_t key(int x, int y, int z) const {
    return (static_cast<uint64_t>(x) * n[1] + y) * n[2] + z;
  }
};

// The distance search's questions to keep_going: one per 64 k units of work (segments gathered
// or sorted, pairs compared: a draft's millions take seconds), and once it said stop, stop ever
// after.
struct SearchPoll {
  static constexpr uint64_t kWorkPerPoll = uint64_t{1} << 16;
  const std::function<bool(uint64_t, uint64_t)>& keep_going;
  uint64_t work = 0, next = 0;
  bool halted = false;
  // 'units' more done; true when the search is to stop. (done, total) go to keep_going.
  bool stop(uint64_t units, uint64_t done = 0, uint64_t total = 1) {
    work += units;
    if (halted || !keep_going || work < next) return halted;
    next = work + kWorkPerPoll;
    return halted = !keep_going(done, total);
  }
};

// The grid of cells 'size' or larger over the extent, its segments sorted by cell; empty (no
// keys) when the poll says stop.
SegmentGrid grid_of(std::vector<Seg> segs, const double extent[3], double ylo, double size,
                    SearchPoll& poll) {
  SegmentGrid g;
  for (int a = 0; a < 3; ++a) {
    g.n[a] = static_cast<int>(std::clamp(std::floor(extent[a] / size), 1.0, double(1 << 20)));
    g.cell[a] = extent[a] / g.n[a];
  }
  g.lo[0] = -0.5 * extent[0], g.lo[1] = ylo, g.lo[2] = -0.5 * extent[2];
  std::vector<std::pair<uint64_t, uint32_t>> by_cell(segs.size());
  for (uint32_t i = 0; i < segs.size(); ++i) {
    if (poll.stop(1)) return {};
    const Vec3 m = 0.5 * (segs[i].a + segs[i].b);
    by_cell[i] = {g.key(g.index(0, m.x), g.index(1, m.y), g.index(2, m.z)), i};
  }
  std::sort(by_cell.begin(), by_cell.end());
  g.segs.reserve(segs.size());
  for (size_t k = 0; k < by_cell.size(); ++k) {
    if (poll.stop(1)) return {};
    if (k == 0 || by_cell[k].first != by_cell[k - 1].first) {
      g.keys.push_back(by_cell[k].first);
      g.cell_start.push_back(k);
    }
    g.segs.push_back(segs[by_cell[k].second]);
  }
  g.cell_start.push_back(by_cell.size());
  return g;
}

}  // namespace

double min_fiber_distance(const FiberCurves& fibers, double period_x, double period_z,
                          double cutoff,
                          const std::function<bool(uint64_t, uint64_t)>& keep_going) {
  std::vector<Seg> segs;
  segs.reserve(fibers.segment_count());
  double ylo = 1e300, yhi = -1e300, longest = 0;
  SearchPoll poll{keep_going};
  for (size_t c = 0; c < fibers.curve_count(); ++c) {
    if (poll.stop(fibers.curve_points[c])) return cutoff;
    for (uint32_t k = 0; k + 1 < fibers.curve_points[c]; ++k) {
      const Vec3 a = fibers.point(fibers.curve_first[c] + k),
                 b = fibers.point(fibers.curve_first[c] + k + 1);
      Seg s{a, b, {}, {}, static_cast<uint32_t>(c), k};
      for (int i = 0; i < 3; ++i) {
        s.lo[i] = std::min(a[i], b[i]) - 0.5 * cutoff;
        s.hi[i] = std::max(a[i], b[i]) + 0.5 * cutoff;
        longest = std::max(longest, std::abs(b[i] - a[i]));
      }
      ylo = std::min(ylo, s.lo.y);
      yhi = std::max(yhi, s.hi.y);
      segs.push_back(s);
    }
  }
  if (segs.empty()) return cutoff;
  // Grown boxes that overlap have midpoints at most cutoff + the longest extent apart per axis.
  const double extent[3] = {period_x, std::max(yhi - ylo, cutoff), period_z};
  double min_segment = 1e300;
  for (const Seg& s : segs) min_segment = std::min(min_segment, length(s.b - s.a));
  const SegmentGrid g = grid_of(std::move(segs), extent, ylo, cutoff + longest, poll);
  if (poll.halted) return cutoff;
  // Segments of a fiber and its continuation within the cutoff of their joint are neighbours
  // along one fiber, not two fibers.
  const std::vector<int64_t> next = continuations(fibers, period_x, period_z);
  if (poll.stop(fibers.curve_count())) return cutoff;
  const long near = static_cast<long>(std::ceil(cutoff / std::max(min_segment, 1e-15))) + 1;
  // b lies fewer than 'near' segments after a along a's fiber (through the curves continuing it;
  // a nonwoven fiber cut at a corner of the tile continues through a short middle piece).
  auto along_joint = [&](const Seg& a, const Seg& b) {
    long gap = static_cast<long>(fibers.curve_points[a.curve]) - 2 - a.index;
    int64_t c = next[a.curve];
    for (int step = 0; c >= 0 && gap < near && step < 8; ++step) {
      if (c == b.curve) return gap + static_cast<long>(b.index) < near;
      gap += static_cast<long>(fibers.curve_points[c]) - 1;
      c = next[c];
    }
    return false;
  };
  // The nearest periodic image (round(d / period) periods; most pairs need none).
  auto image = [](double d, double period) {
    return std::abs(d) < 0.5 * period ? 0.0 : period * std::round(d / period);
  };
  auto pair_distance = [&](const Seg& a, const Seg& b) {
    if (a.curve == b.curve) return cutoff;
    // The periodic image of b nearest to a; boxes grown by cutoff / 2 that miss each other hold
    // no pair within the cutoff.
    const Vec3 shift{image(0.5 * (a.a.x + a.b.x - b.a.x - b.b.x), period_x), 0,
                     image(0.5 * (a.a.z + a.b.z - b.a.z - b.b.z), period_z)};
    for (int i = 0; i < 3; ++i)
      if (a.hi[i] < b.lo[i] + shift[i] || b.hi[i] + shift[i] < a.lo[i]) return cutoff;
    if (along_joint(a, b) || along_joint(b, a)) return cutoff;
    return segment_distance(a.a, a.b, b.a + shift, b.b + shift);
  };
  double best = cutoff;
  std::vector<uint64_t> seen;
  for (size_t k = 0; k < g.keys.size(); ++k) {
    if (poll.stop(1, k, g.keys.size())) return best;
    const uint64_t key = g.keys[k];
    const int cz = static_cast<int>(key % g.n[2]), cy = static_cast<int>(key / g.n[2] % g.n[1]),
              cx = static_cast<int>(key / g.n[2] / g.n[1]);
    seen.clear();  // a neighbour met twice through the wrap of a short period is done once
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const int y = cy + dy;
          if (y < 0 || y >= g.n[1]) continue;
          const uint64_t other = g.key((cx + dx + g.n[0]) % g.n[0], y, (cz + dz + g.n[2]) % g.n[2]);
          if (other < key || std::find(seen.begin(), seen.end(), other) != seen.end()) continue;
          seen.push_back(other);
          const auto it = std::lower_bound(g.keys.begin(), g.keys.end(), other);
          if (it == g.keys.end() || *it != other) continue;
          const size_t o = static_cast<size_t>(it - g.keys.begin());
          for (uint64_t i = g.cell_start[k]; i < g.cell_start[k + 1]; ++i) {
            const uint64_t first = other == key ? i + 1 : g.cell_start[o];
            for (uint64_t j = first; j < g.cell_start[o + 1]; ++j)
              best = std::min(best, pair_distance(g.segs[i], g.segs[j]));
            if (poll.stop(g.cell_start[o + 1] - std::min(first, g.cell_start[o + 1]), k,
                          g.keys.size()))
              return best;
          }
        }
  }
  return best;
}

SceneDescription fiber_patch_description(WeaveOptions options, const std::string& source,
                                         const std::string& object) {
  options.detail = "fiber";
  SceneDescription d;
  d.source = source;
  auto curves = std::make_shared<FiberCurves>(make_woven_sample(options).fibers);
  curves->names = {object};
  d.curves.push_back(std::move(curves));
  return d;
}

namespace {

// One copy of the fibers into 'c', its points shifted by (dx, 0, dz) a slice at a time, 'progress'
// told the points copied and asked between slices. Near the limit of 3e7 points
// a copy is 480 MB, and new pages came at 60-80 MB/s on the project's shared 2-core machine
// (integrators/src/zero_polled.h): seconds per copy, nine copies or more. False when it said
// stop. The sums are those of one pass (float + float, point by point): the bits do not depend on
// the slices.
bool copy_fibers_polled(const FiberCurves& from, float dx, float dz, uint64_t done_before,
                        uint64_t total, const ProgressCallback& progress, FiberCurves& c) {
  constexpr size_t kSlicePoints = size_t(1) << 19;  // 8 MB of points
  c.curve_first = from.curve_first;
  c.curve_points = from.curve_points;
  c.curve_yarn = from.curve_yarn;
  c.yarn_material = from.yarn_material;
  c.names = from.names;
  const size_t n = from.point_count();
  c.points.reserve(4 * n);
  for (size_t v0 = 0; v0 < n; v0 += kSlicePoints) {
    const size_t v1 = std::min(n, v0 + kSlicePoints);
    c.points.insert(c.points.end(), from.points.begin() + 4 * v0, from.points.begin() + 4 * v1);
    for (size_t v = v0; v < v1; ++v) {
      c.points[4 * v] += dx;
      c.points[4 * v + 2] += dz;
    }
    if (!progress({"scene copies", done_before + v1, total, "fiber points"})) return false;
  }
  return true;
}

}  // namespace

SceneDescription tiled_woven_description(const WovenSample& sample, int half_x, int half_z,
                                         const std::string& source, bool instanced) {
  return *tiled_woven_description(sample, half_x, half_z, source, instanced, no_progress());
}

std::optional<SceneDescription> tiled_woven_description(const WovenSample& sample, int half_x,
                                                        int half_z, const std::string& source,
                                                        bool instanced,
                                                        const ProgressCallback& progress) {
  for (const auto& [half, field] : {std::pair{half_x, "half_x"}, std::pair{half_z, "half_z"}})
    if (half < 0 || half > 64)
      throw Error(source, field, "copies on each side must lie in [0, 64]");
  const double px = sample.summary.period_x_mm * detail::kMetresPerMm;
  const double pz = sample.summary.period_z_mm * detail::kMetresPerMm;
  if (!(px > 0 && pz > 0)) throw Error(source, "sample", "the woven sample has no period");
  const bool fibers = sample.fibers.curve_count() > 0;
  if (!fibers && sample.meshes.empty())
    throw Error(source, "detail", "the woven sample has no geometry (neither fibers nor tubes)");
  SceneDescription d;
  d.source = source;
  // Shifts in double, then rounded once to the geometry's float.
  const auto shift = [&](int i, int k) {
    return std::pair{static_cast<float>(i * px), static_cast<float>(k * pz)};
  };
  if (fibers) {
    const uint64_t per_copy = sample.fibers.point_count();
    const uint64_t total = per_copy * uint64_t(2 * half_x + 1) * uint64_t(2 * half_z + 1);
    uint64_t done = 0;
    for (int i = -half_x; i <= half_x; ++i)
      for (int k = -half_z; k <= half_z; ++k, done += per_copy) {
        const auto [dx, dz] = shift(i, k);
        FiberCurves c;
        if (!copy_fibers_polled(sample.fibers, dx, dz, done, total, progress, c))
          return std::nullopt;
        d.curves.push_back(std::make_shared<const FiberCurves>(std::move(c)));
      }
  } else if (instanced) {
    for (const auto& mesh : sample.meshes) d.meshes.push_back(std::make_shared<TriangleMesh>(mesh));
    for (int i = -half_x; i <= half_x; ++i)
      for (int k = -half_z; k <= half_z; ++k) {
        const auto [dx, dz] = shift(i, k);
        d.mesh_shifts.push_back({dx, 0, dz});
      }
  } else
    for (const auto& mesh : sample.meshes)
      for (int i = -half_x; i <= half_x; ++i)
        for (int k = -half_z; k <= half_z; ++k) {
          const auto [dx, dz] = shift(i, k);
          TriangleMesh m = mesh;
          for (size_t v = 0; v < m.vertex_count(); ++v) {
            m.positions[3 * v] += dx;
            m.positions[3 * v + 2] += dz;
          }
          d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(m)));
        }
  return d;
}

}  // namespace weft
