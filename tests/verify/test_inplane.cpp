// In-plane evaluation of a table (verify/inplane.h): a constant table's beta, the paper's sign,
// and a saturated spectral table reduced to linear sRGB without clipping.
#include <gtest/gtest.h>

#include <cmath>

#include "constant_table.h"
#include "weft/core/math.h"
#include "weft/verify/inplane.h"

using weft::testing::constant_table;

namespace weft {
namespace {

TEST(VerifyInplane, ConstantTableGivesItsBetaEverywhere) {
  const TabulatedBsdfTable t = constant_table(4, 3, 0.37);
  for (double ti : {0.0, 30.0, 70.0}) {
    const auto b = inplane_beta(TableReader(t), ti, {-85, -30, 0, 5, 45, 85}, 7);
    for (const Rgb& c : b) {
      EXPECT_NEAR(c.r, 0.37, 1e-6);
      EXPECT_NEAR(c.b, 0.37, 1e-6);
    }
  }
}

TEST(VerifyInplane, InPlaneDirectionsFollowThePapersSign) {
  // f nonzero only when the view lies on the mirror side (wo.x * wi.x < 0 in the plane phi = 0):
  // views > 0 see it, views < 0 do not.
  const TabulatedBsdfTable t = TabulatedBsdfTable::from_function(
      8, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const double f =
            wo.z > 0 && wi.z > 0 && wo.x * wi.x < 0 && std::abs(wo.y) < 0.3 && std::abs(wi.y) < 0.3
                ? 1.0
                : 0.0;
        for (double& x : v) x = f;
      },
      4, 1, 1);
  const auto b = inplane_beta(TableReader(t), 45, {-45, 45}, 1);
  EXPECT_EQ(b[0].r, 0.0);
  EXPECT_GT(b[1].r, 0.5);
}

// A spectral table that reflects only the 490 nm band (band 10: kNumBands from 390 nm in 10 nm
// steps, core/spectrum.h): a cyan-green far outside the sRGB gamut, whose linear sRGB red is
// negative. The reduction keeps it negative (nothing clipped), counts it, and the in-plane curves
// carry it.
TEST(VerifyInplane, SaturatedSpectralTableKeepsItsNegativeComponents) {
  constexpr int kBand = 10;  // 490 nm
  const TabulatedBsdfTable t = TabulatedBsdfTable::from_function(
      2, kNumBands,
      [](const Vec3&, const Vec3&, std::span<double> v) {
        for (double& x : v) x = 0;
        v[kBand] = 1 / kPi;
      },
      2, 1, 1);
  const Rgb want = bands_to_linear_srgb([](int b) { return b == kBand ? 1 / kPi : 0.0; });
  ASSERT_LT(want.r, 0);  // outside the gamut
  OutOfGamut outside;
  const TabulatedBsdfTable rgb = table_to_rgb(t, &outside);
  ASSERT_EQ(rgb.channels, 3);
  const size_t cells = rgb.values.size() / 3;
  EXPECT_EQ(outside.components, cells);  // one negative component (red) per cell
  EXPECT_NEAR(outside.largest, -want.r, 1e-6);
  for (size_t c = 0; c < cells; ++c) EXPECT_NEAR(rgb.values[c * 3], want.r, 1e-6) << c;
  MeasuredInplane m;
  m.curves.push_back({0, {-30, 0, 30}, {Rgb(0.2), Rgb(0.2), Rgb(0.2)}});
  const auto curves = table_curves(t, m, 3);
  for (const Rgb& b : curves[0]) {
    EXPECT_NEAR(b.r, kPi * want.r, 1e-5);  // beta = pi f, negative as f is
    EXPECT_NEAR(b.g, kPi * want.g, 1e-5);
  }
}

}  // namespace
}  // namespace weft
