#pragma once
// Colour as users state it: CIELAB under D65 for the CIE 1931 2-degree or the CIE 1964 10-degree
// observer, the CIEDE2000 colour difference, and sRGB values decoded to CIE XYZ. The spectral
// bands, the 1931 observer and D65 are core/spectrum.h's; the 10-degree observer is compiled in
// the same way (core/data/cie/README.md).
#include <array>
#include <string>

#include "weft/core/spectrum.h"

namespace weft {

enum class Observer { kCie1931TwoDegree, kCie1964TenDegree };

struct Lab {
  double l = 0, a = 0, b = 0;
  constexpr bool operator==(const Lab&) const = default;
};

// The observer's colour matching functions averaged over each band (1 nm CIE data).
const std::array<Xyz, kNumBands>& cie_cmf_bands(Observer observer);
// A reflectance's colour under D65 for 'observer', Y = 1 for the perfect white reflector.
Xyz reflectance_to_xyz_d65(const Spectrum& reflectance, Observer observer);
// The perfect white reflector under D65 as the bands see it (Y = 1): the white of the CIELAB
// values of reflectances (reflectance_to_lab).
Xyz d65_white(Observer observer);

// CIE 1976 L*a*b* of 'xyz' relative to 'white' (CIE 15:2004, with its linear segment near black)
// and its inverse.
Lab xyz_to_lab(const Xyz& xyz, const Xyz& white);
Xyz lab_to_xyz(const Lab& lab, const Xyz& white);
// The colour of a reflectance under D65 for 'observer', relative to d65_white(observer).
Lab reflectance_to_lab(const Spectrum& reflectance, Observer observer);

// The sRGB white, D65 at the chromaticity IEC 61966-2-1 states (x 0.3127, y 0.3290), Y = 1.
inline constexpr Xyz kSrgbWhite{0.95047, 1.0, 1.08883};
// sRGB transfer function decoded (IEC 61966-2-1): an encoded component in [0, 1] to linear.
double srgb_gamma_to_linear(double encoded);
// Linear sRGB to XYZ (the inverse of xyz_to_linear_srgb's IEC matrix).
Xyz linear_srgb_to_xyz(const Rgb& linear);
// CIELAB of a linear sRGB colour relative to the sRGB white: (1, 1, 1) is L* 100, a* = b* = 0.
Lab linear_srgb_to_lab(const Rgb& linear);

// CIEDE2000 (CIE 142-2001), kL = kC = kH = 1, as Sharma, Wu and Dalal (2005) state it; symmetric.
double delta_e00(const Lab& x, const Lab& y);

// "L a b" with one decimal, e.g. "(45.2, 60.1, 30.0)".
std::string format_lab(const Lab& lab);

}  // namespace weft
