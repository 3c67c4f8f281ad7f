#pragma once
// What the ray-traced fabric estimator's tests share (test_fabric_raytrace.cpp,
// test_raytrace_estimators.cpp): small fiber tables, options, the bundled sample, and z-scores of
// two runs cell by cell.
#include <cmath>
#include <cstdint>
#include <span>

#include "weft/core/direction_grid.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/scenes/weave.h"

namespace weft::testing {

// A fiber table given per point: f(wo, wi) in every channel.
template <class F>
TabulatedBsdfTable fiber_table(int resolution, F f) {
  auto t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) { v[0] = v[1] = v[2] = f(wo, wi); },
      2, 1);
  t.kind = "fiber";
  return t;
}

// A fiber table given per point and channel.
template <class F>
TabulatedBsdfTable fiber_table3(int resolution, F f) {
  auto t = TabulatedBsdfTable::from_function(resolution, 3, f, 2, 1);
  t.kind = "fiber";
  return t;
}

inline FabricRaytraceOptions options(int resolution, uint64_t particles_per_bin) {
  FabricRaytraceOptions o;
  o.resolution = resolution;
  o.particles_per_bin = particles_per_bin;
  return o;
}

// A lossless-shaped "fiber": every point sends a fraction of the light to its outer hemisphere.
inline TabulatedBsdfTable uniform_fiber(int resolution, double f) {
  return fiber_table(resolution, [f](const Vec3& wo, const Vec3&) { return wo.z > 0 ? f : 0.0; });
}

// The bundled red-cotton sample at yarn or fiber detail, with 'extra' options over it.
inline WovenSample default_sample(const char* detail = "yarn", const WeaveOptions& extra = {}) {
  WeaveOptions o = extra;
  o.detail = detail;
  return make_woven_sample(overlay(red_cotton_weave_options(), o));
}

// A reciprocal fiber table, unchanged when the fiber's axis is reversed (x, y -> -x, -y): more
// light to the outer side, a little transmitted, a dependence on the azimuth about the axis.
inline TabulatedBsdfTable reciprocal_fiber(int resolution) {
  return fiber_table(resolution, [](const Vec3& wo, const Vec3& wi) {
    auto g = [](double z) { return z > 0 ? 1.0 : 0.5; };
    return g(wo.z) * g(wi.z) * (0.25 + 0.1 * wo.x * wi.x) * kInvPi;
  });
}

// z-scores of a against b cell by cell, with the stated standard errors; cells where either has
// fewer than about 25 exits (standard error above a fifth of the value) are left out.
struct ZStats {
  double rms = 0;
  double beyond4 = 0;  // fraction with |z| > 4
  size_t cells = 0;
};
template <class Map>
ZStats z_scores(const FabricRaytraceResult& a, const FabricRaytraceResult& b, Map map) {
  const int bins = a.table.bins(), nc = a.table.channels;
  ZStats z;
  double sum2 = 0;
  size_t far = 0;
  for (int i = 0; i < bins; ++i)
    for (int o = 0; o < bins; ++o) {
      const auto [bi, bo] = map(i, o);
      for (int c = 0; c < nc; ++c) {
        const size_t va = (static_cast<size_t>(i) * bins + o) * nc + c,
                     vb = (static_cast<size_t>(bi) * bins + bo) * nc + c;
        const double fa = a.table.values[va], fb = b.table.values[vb];
        const double sa = a.standard_error[va], sb = b.standard_error[vb];
        if (!(sa > 0 && sb > 0 && sa < 0.2 * fa && sb < 0.2 * fb)) continue;
        const double zz = (fa - fb) / std::sqrt(sa * sa + sb * sb);
        sum2 += zz * zz;
        far += std::abs(zz) > 4;
        ++z.cells;
      }
    }
  z.rms = z.cells ? std::sqrt(sum2 / z.cells) : 0;
  z.beyond4 = z.cells ? double(far) / z.cells : 0;
  return z;
}

// A lossless fiber shaped like a clear one: what a point returns depends on where the light's line
// crosses the fiber. Light along a line at impact u (in radii) through a round fiber comes, in the
// frames of B' and B'' alike, from a direction with q = wi_z^2 / (wi_y^2 + wi_z^2) = 1 - u^2;
// A(wi) = 1/2 + 1.2 (q^4 - 128/315), sent evenly to the outer hemisphere. A' + A'' is 2.4 on
// lines through the axis and 0.02 at the edges, and 1 averaged over u at every line direction
// (the mean of (1 - u^2)^4 is 128/315): the total albedo is 1, 0.988 tabulated at R = 8.
inline TabulatedBsdfTable clear_lossless_fiber(int resolution) {
  return fiber_table(resolution, [](const Vec3& wo, const Vec3& wi) {
    const double across2 = wi.y * wi.y + wi.z * wi.z;
    const double q = across2 > 0 ? wi.z * wi.z / across2 : 0.0;
    return wo.z > 0 ? (0.5 + 1.2 * (std::pow(q, 4) - 128.0 / 315)) * kInvPi : 0.0;
  });
}

// One incident bin of a ray-traced table, as the channels' mean (the books count the mean): the
// table's directional albedo (reflected + transmitted) and its standard error (from the cells',
// taken as independent; the mean's at most the channels' mean), and the fraction of the launched
// power that the books say exited.
struct BinEnergy {
  double albedo = 0, sigma = 0, exited = 0;
};
inline BinEnergy bin_energy(const FabricRaytraceResult& r, int bin) {
  const DirectionGrid g = r.table.grid();
  const auto d = g.cosine_weighted_areas();
  const int nc = r.table.channels;
  const auto a = r.table.directional_albedo(bin);
  BinEnergy e;
  for (int c = 0; c < nc; ++c) {
    double var = 0;
    for (int o = 0; o < g.bins(); ++o)
      var += std::pow(r.standard_error[r.table.index(bin, o, c)] * d[o], 2);
    e.albedo += a.total(c) / nc;
    e.sigma += std::sqrt(var) / nc;
  }
  const FabricBinBooks& b = r.bin_books[bin];
  e.exited = b.exited / b.launched;
  return e;
}

}  // namespace weft::testing
