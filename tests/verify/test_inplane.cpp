// In-plane evaluation of a table (verify/inplane.h): a constant table's beta, the paper's sign.
#include <gtest/gtest.h>

#include <cmath>

#include "constant_table.h"
#include "weft/verify/inplane.h"

using weft::testing::constant_table;

namespace weft {
namespace {

TEST(VerifyInplane, ConstantTableGivesItsBetaEverywhere) {
  const TabulatedBsdfTable t = constant_table(4, 3, 0.37);
  for (double ti : {0.0, 30.0, 70.0}) {
    const auto b = inplane_beta(t, ti, {-85, -30, 0, 5, 45, 85}, 7);
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
  const auto b = inplane_beta(t, 45, {-45, 45}, 1);
  EXPECT_EQ(b[0].r, 0.0);
  EXPECT_GT(b[1].r, 0.5);
}

}  // namespace
}  // namespace weft
