#pragma once
// Spectral bands of the project: 390-710 nm in 10 nm steps (33 bands, the paper's measurement
// grid). Band i is centred at 390 + 10 i nm and covers [centre - 5, centre + 5) nm.
#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>

#include "weft/core/componentwise.h"

namespace weft {

inline constexpr int kNumBands = 33;
inline constexpr double kFirstBandNm = 390.0;
inline constexpr double kBandStepNm = 10.0;

constexpr double band_wavelength_nm(int band) {
  return kFirstBandNm + kBandStepNm * band;
}

using Spectrum = std::array<double, kNumBands>;

struct Xyz {
  double x = 0, y = 0, z = 0;
};
// Linear RGB triple; also the renderer's colour type.
struct Rgb {
  double r = 0, g = 0, b = 0;

  constexpr Rgb() = default;
  constexpr Rgb(double r_, double g_, double b_) : r(r_), g(g_), b(b_) {}
  constexpr explicit Rgb(double v) : r(v), g(v), b(v) {}
  // Channel k: 0 = r, 1 = g, 2 = b (loops over channels).
  constexpr double operator[](int k) const { return k == 0 ? r : (k == 1 ? g : b); }
  constexpr double& operator[](int k) { return k == 0 ? r : (k == 1 ? g : b); }
  constexpr Rgb& operator+=(const Rgb& o) {
    r += o.r;
    g += o.g;
    b += o.b;
    return *this;
  }
  constexpr Rgb& operator*=(const Rgb& o) {
    r *= o.r;
    g *= o.g;
    b *= o.b;
    return *this;
  }
  constexpr Rgb& operator*=(double s) {
    r *= s;
    g *= s;
    b *= s;
    return *this;
  }
  constexpr double max_component() const { return r > g ? (r > b ? r : b) : (g > b ? g : b); }
  constexpr double average() const { return (r + g + b) / 3.0; }
  constexpr bool is_black() const { return r == 0 && g == 0 && b == 0; }
  // Equal components: the one colour that is also a spectrum (the same value at every band).
  constexpr bool is_grey() const { return r == g && g == b; }
  constexpr bool operator==(const Rgb&) const = default;
};
// a + b, a * b (per channel), c * s, s * c and c / s (componentwise.h).
template <>
inline constexpr bool kComponentWise<Rgb> = true;

struct Hsv {
  double h = 0, s = 0, v = 0;  // each in [0, 1]
};

// A band's value from a 1 nm table: the trapezoid average of value_at_nm over [centre - 5,
// centre + 5] nm (how the CIE tables and users' spectra are reduced to the bands).
double band_mean_1nm(int band, const std::function<double(int nm)>& value_at_nm);

// CIE 1931 2-degree colour matching functions averaged over each band (1 nm CIE data).
const std::array<Xyz, kNumBands>& cie_cmf_bands();
// CIE D65 relative spectral power averaged over each band.
const Spectrum& d65_bands();

// Colour of a reflectance (or radiance factor) spectrum under D65, normalized so that a
// perfect white reflector has Y = 1.
Xyz reflectance_to_xyz_d65(const Spectrum& reflectance);
// Linear sRGB (D65 white) from XYZ (IEC 61966-2-1 matrix).
Rgb xyz_to_linear_srgb(const Xyz& xyz);
// Gamma-encoded sRGB component from linear.
double linear_to_srgb_gamma(double linear);
// HSV of an RGB triple (each component clamped to >= 0 before conversion is NOT done: negative
// inputs, out of gamut, are reported as they are; callers decide).
Hsv rgb_to_hsv(const Rgb& rgb);

// Spectrum -> linear sRGB weights per band: rgb = sum_b w[b] * value[b], for rendering
// spectral tables in an RGB renderer under D65. White reflectance 1 gives (0.99942, 1.00036,
// 0.99878), not exactly (1, 1, 1): the IEC matrix's white is D65's chromaticity, not that of the
// 10 nm CIE 1931 and D65 tables summed here (no white balance is applied).
const std::array<Rgb, kNumBands>& srgb_band_weights_d65();

// The one spectral -> RGB reduction of tabulated quantities (BSDF tables, albedos): linear sRGB
// under D65 of the band values value_of_band(0 .. kNumBands - 1). Saturated spectra can give
// negative components (outside the sRGB gamut); GamutClip removes them.
template <class ValueOfBand>
Rgb bands_to_linear_srgb(ValueOfBand&& value_of_band) {
  const auto& w = srgb_band_weights_d65();
  Rgb c;
  for (int b = 0; b < kNumBands; ++b) c += w[b] * static_cast<double>(value_of_band(b));
  return c;
}

// Sets negative components to 0 (a reflectance or BSDF cannot be negative), counting what it
// removed so that callers can report it.
struct GamutClip {
  size_t components = 0;  // components set to 0
  double largest = 0;     // largest magnitude removed

  void clip(Rgb& c) {
    for (double* v : {&c.r, &c.g, &c.b})
      if (*v < 0) {
        largest = std::max(largest, -*v);
        ++components;
        *v = 0;
      }
  }
};

}  // namespace weft
