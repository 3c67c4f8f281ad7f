// The energy a table returns: the cosine-weighted area of each bin, split at the horizon, and the
// directional albedo of a wi bin, against analytic BSDFs whose albedo is known in closed form. A
// Lambert BSDF of reflectance rho reflects rho at every incidence, since int (rho / pi)
// |cos theta_o| d w_o over a hemisphere is rho.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/lambert.h"

using namespace weft;

namespace {

// Bins that hold directions on both sides of the horizon.
bool straddles(const OctahedralGrid::CosineWeightedArea& d) {
  return d.upper > 0 && d.lower > 0;
}

// How far the albedo of a table whose f lies in [0, f_max] and is constant over every cell pair
// that does not straddle the horizon can be off, for light from a bin wholly on one side: only the
// exit bins that straddle are averages over both sides, and each can move at most f_max times its
// cosine-weighted area on one side between reflection and transmission (or lose it).
double straddle_bound(const OctahedralGrid& g, double f_max) {
  double upper = 0, lower = 0;
  for (const auto& d : g.cosine_weighted_areas_by_side())
    if (straddles(d)) upper += d.upper, lower += d.lower;
  return f_max * std::max(upper, lower) + 1e-6 * f_max * kPi;  // + float storage of the cells
}

// A table of f in every channel (cosine-weighted cell averages, 16 samples per cell pair).
TabulatedBsdfTable table_of(int resolution,
                            const std::function<double(const Vec3& wo, const Vec3& wi)>& f) {
  return TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) { v[0] = v[1] = v[2] = f(wo, wi); },
      16, 3);
}

}  // namespace

TEST(OctahedralGrid, CosineWeightedAreasSumToPiOnEachSide) {
  for (int r : {1, 2, 3, 7, 16, 64}) {
    const OctahedralGrid g{r};
    const auto by_side = g.cosine_weighted_areas_by_side();
    const auto totals = g.cosine_weighted_areas();
    ASSERT_EQ(by_side.size(), static_cast<size_t>(g.bins()));
    double upper = 0, lower = 0;
    for (size_t b = 0; b < by_side.size(); ++b) {
      EXPECT_GE(by_side[b].upper, 0.0);
      EXPECT_GE(by_side[b].lower, 0.0);
      EXPECT_EQ(by_side[b].total(), totals[b]);
      upper += by_side[b].upper;
      lower += by_side[b].lower;
    }
    // int over a hemisphere of |cos theta| d omega = pi.
    EXPECT_NEAR(upper, kPi, 1e-12) << "R " << r;
    EXPECT_NEAR(lower, kPi, 1e-12) << "R " << r;
  }
  // R = 2: each bin is one quadrant of azimuth of the whole sphere, pi / 4 on each side.
  for (const auto& d : OctahedralGrid{2}.cosine_weighted_areas_by_side()) {
    EXPECT_NEAR(d.upper, kPi / 4, 1e-15);
    EXPECT_NEAR(d.lower, kPi / 4, 1e-15);
  }
}

TEST(OctahedralGrid, CosineWeightedAreasMatchIntegrationOverTheMap) {
  // Midpoint rule on the bin's square through to_direction (the map itself): every sub-cell has
  // solid angle 4 pi / (R n)^2. Its error is O(1 / n^2) away from the kinks of |cos theta| (the
  // horizon and the axes), first order along them: 2e-5 of the total at n = 400.
  const int r = 5, n = 400;
  const OctahedralGrid g{r};
  const auto by_side = g.cosine_weighted_areas_by_side();
  for (int b = 0; b < g.bins(); ++b) {
    const int x = b % r, y = b / r;
    double upper = 0, lower = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double z =
            OctahedralGrid::to_direction({(x + (i + 0.5) / n) / r, (y + (j + 0.5) / n) / r}).z;
        (z > 0 ? upper : lower) += std::abs(z);
      }
    const double cell = 4 * kPi / (static_cast<double>(r) * r * n * n);
    EXPECT_NEAR(by_side[b].upper, upper * cell, 2e-5 * kPi) << "bin " << b;
    EXPECT_NEAR(by_side[b].lower, lower * cell, 2e-5 * kPi) << "bin " << b;
  }
}

TEST(TableDirectionalAlbedo, LambertReflectsRhoAtEveryIncidence) {
  // Light from a bin that straddles the horizon arrives from both sides in every one of its cells,
  // so no cell pair there is exact and the bound above says nothing; those bins are left out.
  const double rho = 0.6;
  const LambertBsdf lambert{Rgb(rho)};
  const auto t =
      table_of(16, [&](const Vec3& wo, const Vec3& wi) { return lambert.eval(wo, wi).g; });
  const OctahedralGrid g = t.grid();
  const auto d = g.cosine_weighted_areas_by_side();
  const double bound = straddle_bound(g, rho / kPi);
  EXPECT_LT(bound, 0.05 * rho);  // the checks below must be able to fail
  int checked = 0;
  for (int wi = 0; wi < g.bins(); ++wi) {
    if (straddles(d[wi])) continue;
    const auto a = t.directional_albedo(wi);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(a.total(c), rho, bound) << "wi bin " << wi;
      EXPECT_LE(a.reflectance[c], rho + 1e-6 * rho) << "wi bin " << wi;
      EXPECT_GE(a.reflectance[c], rho - bound) << "wi bin " << wi;
      EXPECT_LE(a.transmittance[c], bound) << "wi bin " << wi;
    }
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

TEST(TableDirectionalAlbedo, TransmissionOnlyTableTransmitsAtNormalIncidence) {
  // f = tau / pi between opposite sides only: light from either normal is all transmitted.
  const double tau = 0.8;
  const auto t = table_of(
      16, [&](const Vec3& wo, const Vec3& wi) { return wo.z * wi.z < 0 ? tau * kInvPi : 0.0; });
  const OctahedralGrid g = t.grid();
  const double bound = straddle_bound(g, tau / kPi);
  for (const Vec3& wi : {Vec3{0, 0, 1}, Vec3{0, 0, -1}}) {
    const auto a = t.directional_albedo(g.bin_of(wi));
    EXPECT_NEAR(a.total(0), tau, bound);
    EXPECT_LE(a.transmittance[0], tau + 1e-6 * tau);
    EXPECT_GE(a.transmittance[0], tau - bound);
    EXPECT_LE(a.reflectance[0], bound);
  }
}

TEST(TableDirectionalAlbedo, SumsOverExitsNotOverIncidentDirections) {
  // f = a / pi for light from above (wi.z > 0), whatever the exit, and 0 for light from below:
  // light from the normal leaves with albedo 2a (a reflected, a transmitted) and light from below
  // with none. A sum over incident directions for the normal exit bin would give a instead. The wi
  // bin of the normal and every wo bin hold f exactly (it is constant over those cell pairs).
  const double a = 0.3;
  const auto t =
      table_of(16, [&](const Vec3&, const Vec3& wi) { return wi.z > 0 ? a / kPi : 0.0; });
  const OctahedralGrid g = t.grid();
  const auto from_above = t.directional_albedo(g.bin_of({0, 0, 1}));
  EXPECT_NEAR(from_above.reflectance[0], a, 1e-6);  // float storage of a / pi
  EXPECT_NEAR(from_above.transmittance[0], a, 1e-6);
  EXPECT_NEAR(from_above.total(0), 2 * a, 2e-6);
  const auto from_below = t.directional_albedo(g.bin_of({0, 0, -1}));
  EXPECT_EQ(from_below.total(0), 0.0);
}

TEST(TableDirectionalAlbedo, RejectsBinsOutsideTheGrid) {
  const auto t = table_of(2, [](const Vec3&, const Vec3&) { return 1.0; });
  EXPECT_NE(weft::testing::error_of([&] { t.directional_albedo(4); }).find("wi_bin"),
            std::string::npos);
  EXPECT_NE(weft::testing::error_of([&] { t.directional_albedo(-1); }), "");
}
