// What a d/8 instrument reads of a material (materials/colour_reading.h): a table's reflectance
// in the normal's incident bin, a measured fabric's neural fit integrated at 8 degrees, and the
// colour specs that name them.
#include <gtest/gtest.h>

#include "../test_util.h"
#include "rgb_table.h"
#include "weft/core/math.h"
#include "weft/materials/colour_reading.h"

using namespace weft;
using namespace weft::testing;

TEST(ColourReading, ALambertianTableReadsItsAlbedo) {
  const auto dir = fresh_test_dir();
  // f = rho / pi on the upper side: its directional-hemispherical reflectance is rho exactly.
  const Rgb rho{0.5, 0.25, 0.1};
  const TabulatedBsdfTable t = rgb_table(6, [&](const Vec3& wo, const Vec3& wi) {
    return wo.z * wi.z > 0 ? rho * (1 / kPi) : Rgb(0.0);
  });
  const std::vector<double> r = table_d8_reflectance(t);
  ASSERT_EQ(r.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], rho[k], 1e-3 * rho[k]);
  t.write_exr(dir / "lambert.exr");
  const ColourTarget target =
      read_colour_target("table:" + (dir / "lambert.exr").string(), "--colour");
  EXPECT_LT(delta_e00(target.lab, linear_srgb_to_lab(rho)), 0.05);
}

TEST(ColourReading, TheMeasuredRedFabricReadsRedAndTheQuadratureHasConverged) {
  const NbrdfNetwork net = NbrdfNetwork::load(find_measured_nbrdf("merl-red-fabric"));
  const Rgb fine = nbrdf_d8_reflectance(net), coarse = nbrdf_d8_reflectance(net, 48);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(fine[k], 0);
    EXPECT_LT(fine[k], 1);  // a reflectance
    EXPECT_NEAR(coarse[k], fine[k], 0.01 * fine[k]);
  }
  EXPECT_GT(fine.r, 2 * fine.g);  // red cloth
  const ColourTarget t = read_colour_target("measured:merl-red-fabric", "--colour");
  EXPECT_EQ(t.lab, linear_srgb_to_lab(fine));
  EXPECT_NE(error_of([] {
              read_colour_target("measured:no-such-fabric", "--colour");
            }).find("no-such-fabric"),
            std::string::npos);
}
