// The energy a table returns: the directional albedo of a wi bin, split into reflection and
// transmission, against analytic BSDFs whose albedo is known in closed form. A Lambert BSDF of
// reflectance rho reflects rho at every incidence, since int (rho / pi) |cos theta_o| d w_o over a
// hemisphere is rho. No bin straddles the horizon (core/direction_grid.h), so a BSDF constant over
// each hemisphere pair is held exactly by every cell and the albedos are exact to float storage.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/lambert.h"

using namespace weft;

namespace {

// A table of f in every channel (cosine-weighted cell averages, 4 samples per cell pair).
TabulatedBsdfTable table_of(int resolution,
                            const std::function<double(const Vec3& wo, const Vec3& wi)>& f) {
  return TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) { v[0] = v[1] = v[2] = f(wo, wi); },
      4, 3);
}

}  // namespace

TEST(TableDirectionalAlbedo, LambertReflectsRhoAtEveryIncidence) {
  const double rho = 0.6;
  const LambertBsdf lambert{Rgb(rho)};
  const auto t =
      table_of(8, [&](const Vec3& wo, const Vec3& wi) { return lambert.eval(wo, wi).g; });
  const DirectionGrid g = t.grid();
  for (int wi = 0; wi < g.bins(); ++wi) {
    const auto a = t.directional_albedo(wi);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(a.reflectance[c], rho, 1e-6 * rho) << "wi bin " << wi;
      EXPECT_EQ(a.transmittance[c], 0.0) << "wi bin " << wi;
    }
  }
}

TEST(TableDirectionalAlbedo, TransmissionOnlyTableTransmitsAtEveryIncidence) {
  // f = tau / pi between opposite sides only: all light is transmitted, from either side.
  const double tau = 0.8;
  const auto t = table_of(
      8, [&](const Vec3& wo, const Vec3& wi) { return wo.z * wi.z < 0 ? tau * kInvPi : 0.0; });
  const DirectionGrid g = t.grid();
  for (int wi = 0; wi < g.bins(); ++wi) {
    const auto a = t.directional_albedo(wi);
    EXPECT_NEAR(a.transmittance[0], tau, 1e-6 * tau) << "wi bin " << wi;
    EXPECT_EQ(a.reflectance[0], 0.0) << "wi bin " << wi;
  }
}

TEST(TableDirectionalAlbedo, SumsOverExitsNotOverIncidentDirections) {
  // f = a / pi for light from above (wi.z > 0), whatever the exit, and 0 for light from below:
  // light from the normal leaves with albedo 2a (a reflected, a transmitted) and light from below
  // with none. A sum over incident directions for the normal exit bin would give a instead.
  const double a = 0.3;
  const auto t = table_of(8, [&](const Vec3&, const Vec3& wi) { return wi.z > 0 ? a / kPi : 0.0; });
  const DirectionGrid g = t.grid();
  const auto from_above = t.directional_albedo(g.bin_of({0, 0, 1}));
  EXPECT_NEAR(from_above.reflectance[0], a, 1e-6);  // float storage of a / pi
  EXPECT_NEAR(from_above.transmittance[0], a, 1e-6);
  EXPECT_NEAR(from_above.total(0), 2 * a, 2e-6);
  const auto from_below = t.directional_albedo(g.bin_of({0, 0, -1}));
  EXPECT_EQ(from_below.total(0), 0.0);
}

TEST(TableDirectionalAlbedo, RejectsBinsOutsideTheGrid) {
  const auto t = table_of(2, [](const Vec3&, const Vec3&) { return 1.0; });
  EXPECT_NE(weft::testing::error_of([&] { t.directional_albedo(8); }).find("wi_bin"),
            std::string::npos);
  EXPECT_NE(weft::testing::error_of([&] { t.directional_albedo(-1); }), "");
}
