#include "weft/materials/table_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/table_reader.h"

namespace weft {
namespace {

constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();

struct Sums {
  double diff2 = 0, ref2 = 0, weight = 0, max_rel = 0;
  size_t cells = 0;
  TableDifference result(int channels) const {
    TableDifference d;
    d.cells = cells;
    d.abs_rms = weight > 0 ? std::sqrt(diff2 / (channels * weight)) : 0.0;
    d.reference_has_light = ref2 > 0;
    d.rel_rms = ref2 > 0 ? std::sqrt(diff2 / ref2) : kUndefined;
    d.max_rel = ref2 > 0 ? max_rel : kUndefined;
    return d;
  }
};

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

void check_compare_reference(const TabulatedBsdfTable& a, const std::string& file) {
  for (float v : a.values)
    if (v != 0) return;
  throw Error(file, "values",
              "the reference table holds no light (every value is 0): a relative difference "
              "against it means nothing; give a reference with light as table A");
}

TableComparison compare_tables(const TabulatedBsdfTable& a, const TabulatedBsdfTable& b,
                               const CompareOptions& o) {
  check_compare_reference(a, "");
  if (a.channels != b.channels)
    throw Error(
        "", "channels",
        "tables differ in bands (" + a.bands() + " and " + b.bands() + "): compare like with like");
  if (a.kind != b.kind)
    throw Error("", "kind", "a " + a.kind + " table and a " + b.kind + " table do not compare");
  const DirectionGrid g{std::max(a.resolution, b.resolution)};
  const auto d = g.cosine_weighted_areas();
  const int nc = a.channels, bins = g.bins();
  // The reference's mean over cells, for the significance threshold of max_rel.
  double mean = 0;
  for (float v : a.values) mean += v;
  mean /= static_cast<double>(a.values.size());
  const double threshold = o.significant * mean;

  // Read as the renderer reads them: a table with a sheen, its rest interpolated plus the sheen.
  const TableReader ra(a), rb(b);
  std::vector<Vec3> centre(bins);
  for (int k = 0; k < bins; ++k) centre[k] = g.bin_center(k);
  Sums all, refl, trans;
  std::vector<double> va(nc), vb(nc);
  for (int i = 0; i < bins; ++i)
    for (int k = 0; k < bins; ++k) {
      ra.eval(centre[k], centre[i], va);
      rb.eval(centre[k], centre[i], vb);
      Sums& side = g.upper(i) == g.upper(k) ? refl : trans;
      const double w = d[i] * d[k];
      for (Sums* s : {&all, &side}) {
        for (int c = 0; c < nc; ++c) {
          s->diff2 += w * sqr(vb[c] - va[c]);
          s->ref2 += w * sqr(va[c]);
          if (va[c] >= threshold && va[c] > 0)
            s->max_rel = std::max(s->max_rel, std::abs(vb[c] - va[c]) / va[c]);
        }
        s->weight += w;
        ++s->cells;
      }
    }
  TableComparison out;
  out.overall = all.result(nc);
  out.reflection = refl.result(nc);
  out.transmission = trans.result(nc);

  double cd2 = 0, cr2 = 0;
  for (double light : o.light_zenith_deg)
    for (double plane : o.plane_azimuth_deg) {
      InPlaneCurve c;
      c.light_zenith_deg = light;
      c.plane_azimuth_deg = plane;
      const double phi = deg_to_rad(plane);
      const Vec3 across{std::cos(phi), std::sin(phi), 0};  // the plane's horizontal axis
      const double ti = deg_to_rad(light);
      const Vec3 wi = std::sin(ti) * across + Vec3{0, 0, std::cos(ti)};
      for (double v = -o.view_max_deg; v <= o.view_max_deg + 1e-9; v += o.view_step_deg) {
        // Positive views lie on the mirror side, opposite the light.
        const double tv = deg_to_rad(v);
        const Vec3 wo = -std::sin(tv) * across + Vec3{0, 0, std::cos(tv)};
        ra.eval(wo, wi, va);
        rb.eval(wo, wi, vb);
        c.view_zenith_deg.push_back(v);
        std::vector<double> ba(nc), bb(nc);
        for (int ch = 0; ch < nc; ++ch) {
          ba[ch] = kPi * va[ch];
          bb[ch] = kPi * vb[ch];
          cd2 += sqr(bb[ch] - ba[ch]);
          cr2 += sqr(ba[ch]);
        }
        c.beta_a.push_back(ba);
        c.beta_b.push_back(bb);
      }
      out.curves.push_back(std::move(c));
    }
  out.in_plane_rel_rms = cr2 > 0 ? std::sqrt(cd2 / cr2) : kUndefined;
  return out;
}

std::string in_plane_csv(const TableComparison& c, const std::vector<std::string>& names) {
  std::ostringstream os;
  os << "light_zenith_deg,plane_azimuth_deg,view_zenith_deg";
  for (const auto& n : names) os << ",a_" << n;
  for (const auto& n : names) os << ",b_" << n;
  os << "\n";
  for (const auto& curve : c.curves)
    for (size_t v = 0; v < curve.view_zenith_deg.size(); ++v) {
      os << fmt(curve.light_zenith_deg) << ',' << fmt(curve.plane_azimuth_deg) << ','
         << fmt(curve.view_zenith_deg[v]);
      for (double x : curve.beta_a[v]) os << ',' << fmt(x);
      for (double x : curve.beta_b[v]) os << ',' << fmt(x);
      os << "\n";
    }
  return os.str();
}

}  // namespace weft
