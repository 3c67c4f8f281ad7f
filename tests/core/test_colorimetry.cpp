#include <gtest/gtest.h>

#include "weft/core/colorimetry.h"

using namespace weft;

namespace {

struct SharmaPair {
  Lab x, y;
  double delta_e00;
};

// G. Sharma, W. Wu and E. N. Dalal, "The CIEDE2000 color-difference formula: implementation
// notes, supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 21-30
// (2005), Table 1: all 34 pairs, chosen to catch the hue wrap, the blue-region rotation and
// near-neutral cases.
constexpr SharmaPair kSharmaPairs[] = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

}  // namespace

TEST(Colorimetry, DeltaE00MatchesSharmaWuDalalTable) {
  for (size_t k = 0; k < std::size(kSharmaPairs); ++k) {
    const SharmaPair& p = kSharmaPairs[k];
    // The table gives four decimals.
    EXPECT_NEAR(delta_e00(p.x, p.y), p.delta_e00, 5e-5) << "pair " << k + 1;
    EXPECT_NEAR(delta_e00(p.y, p.x), p.delta_e00, 5e-5) << "pair " << k + 1 << " swapped";
  }
  EXPECT_EQ(delta_e00({40, 10, -20}, {40, 10, -20}), 0.0);
}

TEST(Colorimetry, D65WhitesMatchTheCieTristimulusValues) {
  // CIE 15:2004 Table T.3: D65 X, Y, Z = 95.04, 100, 108.88 (2 degrees) and 94.81, 100, 107.32
  // (10 degrees). The project's 10 nm bands over 390-710 nm move them by a few tenths.
  const Xyz two = d65_white(Observer::kCie1931TwoDegree);
  const Xyz ten = d65_white(Observer::kCie1964TenDegree);
  EXPECT_NEAR(two.y, 1.0, 1e-12);
  EXPECT_NEAR(ten.y, 1.0, 1e-12);
  EXPECT_NEAR(100 * two.x, 95.04, 0.4);
  EXPECT_NEAR(100 * two.z, 108.88, 0.4);
  EXPECT_NEAR(100 * ten.x, 94.81, 0.4);
  EXPECT_NEAR(100 * ten.z, 107.32, 0.4);
  // The two observers differ (the 10-degree x-bar is bluer): their whites must not coincide.
  EXPECT_GT(std::abs(two.z - ten.z), 0.01);
}

TEST(Colorimetry, TenDegreeBandsSumToTheCieChecksum) {
  // core/data/cie/README.md: the sum of y-bar-10 over 360-830 nm at 1 nm is 116.661877 (the
  // standard's checksum); the bands cover 385-715 nm, outside which y-bar-10 adds less than 0.1.
  double sum = 0;
  for (const Xyz& c : cie_cmf_bands(Observer::kCie1964TenDegree)) sum += c.y * kBandStepNm;
  EXPECT_NEAR(sum, 116.661877, 0.15);
  EXPECT_LT(sum, 116.661877);
}

TEST(Colorimetry, LabRoundTripsAndWhiteIsL100) {
  const Xyz w = d65_white(Observer::kCie1931TwoDegree);
  const Lab white = xyz_to_lab(w, w);
  EXPECT_NEAR(white.l, 100, 1e-9);
  EXPECT_NEAR(white.a, 0, 1e-9);
  EXPECT_NEAR(white.b, 0, 1e-9);
  for (const Xyz c : {Xyz{0.2, 0.1, 0.05}, Xyz{0.001, 0.002, 0.0005}, Xyz{0.9, 0.95, 1.0}}) {
    const Xyz back = lab_to_xyz(xyz_to_lab(c, w), w);
    EXPECT_NEAR(back.x, c.x, 1e-12);
    EXPECT_NEAR(back.y, c.y, 1e-12);
    EXPECT_NEAR(back.z, c.z, 1e-12);
  }
  // CIE 15:2004: L* = 116 (Y/Yn)^(1/3) - 16, so Y = 0.18 (an 18 % grey) is L* 49.50.
  EXPECT_NEAR(xyz_to_lab({0.18 * w.x, 0.18, 0.18 * w.z}, w).l, 49.496, 1e-3);
}

TEST(Colorimetry, SrgbPrimariesHaveTheirPublishedLab) {
  // sRGB red, green and blue in CIELAB (D65, 2 degrees) as B. Lindbloom's calculator and the
  // colour-science literature give them: red (53.24, 80.09, 67.20), green (87.73, -86.18, 83.18),
  // blue (32.30, 79.19, -107.86). The IEC matrix's four digits move them by < 0.05.
  const Lab red = linear_srgb_to_lab({1, 0, 0});
  const Lab green = linear_srgb_to_lab({0, 1, 0});
  const Lab blue = linear_srgb_to_lab({0, 0, 1});
  EXPECT_NEAR(red.l, 53.24, 0.05);
  EXPECT_NEAR(red.a, 80.09, 0.05);
  EXPECT_NEAR(red.b, 67.20, 0.05);
  EXPECT_NEAR(green.l, 87.73, 0.05);
  EXPECT_NEAR(green.a, -86.18, 0.05);
  EXPECT_NEAR(green.b, 83.18, 0.05);
  EXPECT_NEAR(blue.l, 32.30, 0.05);
  EXPECT_NEAR(blue.a, 79.19, 0.1);
  EXPECT_NEAR(blue.b, -107.86, 0.1);
  // IEC 61966-2-1: the encoded 0.5 is linear 0.21404.
  EXPECT_NEAR(srgb_gamma_to_linear(0.5), 0.214041, 1e-6);
  EXPECT_NEAR(srgb_gamma_to_linear(0.04), 0.04 / 12.92, 1e-15);
}

TEST(Colorimetry, AGreyReflectanceIsNeutralForEitherObserver) {
  Spectrum grey;
  grey.fill(0.3);
  for (const Observer o : {Observer::kCie1931TwoDegree, Observer::kCie1964TenDegree}) {
    const Lab lab = reflectance_to_lab(grey, o);
    EXPECT_NEAR(lab.a, 0, 1e-9);
    EXPECT_NEAR(lab.b, 0, 1e-9);
    EXPECT_NEAR(lab.l, 116 * std::cbrt(0.3) - 16, 1e-9);
  }
}
