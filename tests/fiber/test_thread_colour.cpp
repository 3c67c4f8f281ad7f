// A draft's thread colour as a dye of a base fiber (fiber/thread_colour.h): white is the base fiber
// itself, grey a flat reflectance, every colour comes back as itself, red dyes a red fiber
// table, and bad colours are refused by name.
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/fiber/thread_colour.h"

using namespace weft;
using weft::testing::error_of;

namespace {

// The white-balanced linear sRGB of a reflectance under D65 (core/spectrum.h's weights, divided by
// the white reflector's).
Rgb balanced_rgb(const Spectrum& rho) {
  const Rgb c = bands_to_linear_srgb([&](int b) { return rho[b]; });
  const Rgb white = bands_to_linear_srgb([](int) { return 1.0; });
  return {c.r / white.r, c.g / white.g, c.b / white.b};
}

// IEC 61966-2-1's decoding, written out for the test.
double linear_of(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

}  // namespace

TEST(ThreadColour, WhiteIsTheBaseFiberItself) {
  const FiberSpec base = load_fiber_spec("white-cotton");
  const ThreadDye dye = thread_dye({1, 1, 1}, base.fiber_radius_um, "colour");
  for (int b = 0; b < kNumBands; ++b) {
    EXPECT_EQ(dye.reflectance[b], 1.0);
    EXPECT_EQ(dye.absorption_per_um[b], 0.0);
  }
  EXPECT_EQ(fiber_spec_hash_hex(thread_colour_spec(base, {1, 1, 1}, "colour")),
            fiber_spec_hash_hex(base));
  EXPECT_EQ(thread_colour_spec(base, {1, 1, 1}, "colour").name, "white-cotton");
  // Any other colour is a spec of its own, named by its colour.
  const FiberSpec ivory = thread_colour_spec(base, {1, 1, 0.94}, "colour");
  EXPECT_NE(fiber_spec_hash_hex(ivory), fiber_spec_hash_hex(base));
  EXPECT_EQ(ivory.name, "white-cotton #fffff0");
}

TEST(ThreadColour, GreyIsAFlatReflectanceOfItsLinearValue) {
  // Grey's darkness is the same in every block, which sum to 1: rho = the linear value.
  const ThreadDye dye = thread_dye({0.5, 0.5, 0.5}, 8, "colour");
  for (int b = 0; b < kNumBands; ++b) EXPECT_NEAR(dye.reflectance[b], linear_of(0.5), 1e-12) << b;
  // mu_a = -ln(rho) / (pi r / 2): one pass along the mean chord transmits rho.
  EXPECT_NEAR(dye.absorption_per_um[0], -std::log(linear_of(0.5)) / (0.5 * kPi * 8), 1e-12);
}

TEST(ThreadColour, AColourInsideTheBlocksGamutComesBackAsItself) {
  for (const std::array<double, 3> srgb :
       {std::array<double, 3>{0.7, 0.55, 0.4}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}}) {
    const ThreadDye dye = thread_dye(srgb, 8, "colour");
    const Rgb c = balanced_rgb(dye.reflectance);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], linear_of(srgb[i]), 1e-9) << i;
  }
}

TEST(ThreadColour, EveryColourOfTheCubeIsAReflectance) {
  // The header's claim that M^-1 W has no negative entry: rho in [0, 1] over a lattice of the
  // sRGB cube (its corners included, where a negative entry would show first).
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int k = 0; k <= 10; ++k)
        for (double r : thread_dye({i / 10.0, j / 10.0, k / 10.0}, 8, "c").reflectance) {
          ASSERT_GE(r, -1e-12) << i << " " << j << " " << k;
          ASSERT_LE(r, 1 + 1e-12) << i << " " << j << " " << k;
        }
}

TEST(ThreadColour, PureRedAbsorbsBlueAndGreenNotRed) {
  const ThreadDye dye = thread_dye({1, 0, 0}, 8, "colour");
  // 440 nm and 540 nm absorb at the floor's rate, -ln(0.01) per mean chord; 690 nm hardly.
  const double floor_per_um = -std::log(kThreadMinReflectance) / (0.5 * kPi * 8);
  EXPECT_GT(dye.absorption_per_um[5], 0.5 * floor_per_um);
  EXPECT_GT(dye.absorption_per_um[15], 0.5 * floor_per_um);
  EXPECT_LT(dye.absorption_per_um[30], 0.1 * floor_per_um);
}

TEST(ThreadColour, ARedThreadDyesARedFiberTable) {
  // White cotton dyed by a red thread's rule: the baked fiber table's albedo is red (R/G > 1),
  // while white cotton's is grey (its R/G within 5 % of 1: an undyed fibre, docs/presets.md).
  const FiberSpec base = load_fiber_spec("white-cotton");
  FiberTableBakeOptions o{.resolution = 4, .photons_per_band = 300, .threads = 1, .passes = 2};
  o.spectral = false;
  const auto white = bake_fiber_table(base, o).table.total_albedo();
  const auto red =
      bake_fiber_table(thread_colour_spec(base, {0.8, 0.1, 0.1}, "colour"), o).table.total_albedo();
  EXPECT_NEAR(white[0] / white[1], 1.0, 0.05);
  EXPECT_GT(red[0] / red[1], 1.5);
  EXPECT_GT(red[0] / red[2], 1.5);
  EXPECT_LT(red[1], white[1]);
}

TEST(ThreadColour, BadColoursAreRefusedByName) {
  EXPECT_NE(error_of([] {
              thread_dye({1.2, 0, 0}, 8, "[WARP COLORS] 3");
            }).find("[WARP COLORS] 3"),
            std::string::npos);
  EXPECT_NE(error_of([] { thread_dye({NAN, 0, 0}, 8, "c"); }).find("[0, 1]"), std::string::npos);
  EXPECT_EQ(srgb_hex({1, 0.5, 0}), "#ff8000");
}
