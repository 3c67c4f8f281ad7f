// Colour (verify/colour.h, verify/inplane.h table_to_rgb): grey stays neutral.
#include <gtest/gtest.h>

#include <numbers>

#include "constant_table.h"
#include "weft/verify/colour.h"
#include "weft/verify/inplane.h"

using weft::testing::constant_table;

namespace weft {
namespace {

TEST(VerifyColour, WhiteAndGreyAreNeutral) {
  Spectrum s;
  s.fill(0.5);
  const ColourEntry e = colour_of_spectrum("grey", s, "");
  EXPECT_NEAR(e.rgb.r, 0.5, 2e-3);  // D65 white -> sRGB white (spectrum.h)
  EXPECT_NEAR(e.rgb.g, 0.5, 2e-3);
  EXPECT_NEAR(e.rgb.b, 0.5, 2e-3);
  EXPECT_LT(e.hsv.s, 0.01);
  // A spectral constant table converts to equal RGB channels.
  const TabulatedBsdfTable rgb = table_to_rgb(constant_table(2, kNumBands, 1.0));
  EXPECT_EQ(rgb.channels, 3);
  EXPECT_NEAR(rgb.values[0], 1.0 / std::numbers::pi, 1e-3);
  EXPECT_NEAR(rgb.values[2], 1.0 / std::numbers::pi, 1e-3);
}

}  // namespace
}  // namespace weft
