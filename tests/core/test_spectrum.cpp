#include <gtest/gtest.h>

#include "weft/core/spectrum.h"

using namespace weft;

TEST(Spectrum, BandsCover390To710) {
  EXPECT_EQ(kNumBands, 33);
  EXPECT_DOUBLE_EQ(band_wavelength_nm(0), 390.0);
  EXPECT_DOUBLE_EQ(band_wavelength_nm(32), 710.0);
}

TEST(Spectrum, CmfBandSumMatchesCieTotal) {
  // core/data/cie/README.md (the CIE 1931 2 deg dataset): sum of ybar over 360-830 nm at 1 nm =
  // 106.8569.
  // The bands cover 385-715 nm; ybar outside that range adds less than 0.05.
  double sum = 0;
  for (const auto& c : cie_cmf_bands()) sum += c.y * kBandStepNm;
  EXPECT_NEAR(sum, 106.8569, 0.1);
  EXPECT_LT(sum, 106.8569);
}

TEST(Spectrum, WhiteUnderD65HasD65Chromaticity) {
  Spectrum white;
  white.fill(1.0);
  const Xyz xyz = reflectance_to_xyz_d65(white);
  EXPECT_NEAR(xyz.y, 1.0, 1e-12);
  // CIE 15:2004: D65 white point x = 0.31272, y = 0.32903 (2 degree observer). 10 nm banding over
  // 390-710 nm moves it by less than 2e-3.
  const double sum = xyz.x + xyz.y + xyz.z;
  EXPECT_NEAR(xyz.x / sum, 0.31272, 2e-3);
  EXPECT_NEAR(xyz.y / sum, 0.32903, 2e-3);
  const Rgb rgb = xyz_to_linear_srgb(xyz);
  EXPECT_NEAR(rgb.r, 1.0, 0.02);
  EXPECT_NEAR(rgb.g, 1.0, 0.02);
  EXPECT_NEAR(rgb.b, 1.0, 0.02);
}

TEST(Spectrum, HsvOfPrimaries) {
  const Hsv red = rgb_to_hsv({0.8, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(red.h, 0.0);
  EXPECT_DOUBLE_EQ(red.s, 1.0);
  EXPECT_DOUBLE_EQ(red.v, 0.8);
  const Hsv blue = rgb_to_hsv({0.0, 0.0, 1.0});
  EXPECT_NEAR(blue.h, 2.0 / 3.0, 1e-12);
  const Hsv grey = rgb_to_hsv({0.5, 0.5, 0.5});
  EXPECT_DOUBLE_EQ(grey.s, 0.0);
}

TEST(Spectrum, RedReflectorHasRedHue) {
  Spectrum s{};
  for (int b = 0; b < kNumBands; ++b) s[b] = band_wavelength_nm(b) > 600 ? 0.6 : 0.02;
  const Hsv hsv = rgb_to_hsv(xyz_to_linear_srgb(reflectance_to_xyz_d65(s)));
  EXPECT_TRUE(hsv.h < 0.05 || hsv.h > 0.95) << hsv.h;
  EXPECT_GT(hsv.s, 0.8);
}

TEST(Spectrum, SrgbBandWeightsSumToWhite) {
  double r = 0, g = 0, b = 0;
  for (const auto& w : srgb_band_weights_d65()) {
    r += w.r;
    g += w.g;
    b += w.b;
  }
  const Rgb white = xyz_to_linear_srgb(reflectance_to_xyz_d65([] {
    Spectrum s;
    s.fill(1);
    return s;
  }()));
  EXPECT_NEAR(r, white.r, 1e-12);
  EXPECT_NEAR(g, white.g, 1e-12);
  EXPECT_NEAR(b, white.b, 1e-12);
}
