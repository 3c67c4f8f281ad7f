#include "weft/fiber/thread_colour.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "weft/core/colorimetry.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/optimize.h"

namespace weft {
namespace {

// The blocks' edges (nm) and the width of their raised-cosine transitions: sRGB's blue, green and
// red primaries have dominant wavelengths near 465, 550 and 610 nm.
constexpr double kBlueGreenNm = 490, kGreenRedNm = 590, kEdgeWidthNm = 40;

// 0 below edge - width / 2, 1 above edge + width / 2, a raised cosine between.
double smooth_step(double lambda_nm, double edge_nm) {
  const double x = (lambda_nm - edge_nm) / kEdgeWidthNm + 0.5;
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  return 0.5 * (1 - std::cos(kPi * x));
}

// Block k (0 red, 1 green, 2 blue) at band b; the three sum to 1.
double block(int k, int b) {
  const double l = band_wavelength_nm(b);
  const double red = smooth_step(l, kGreenRedNm), blue = 1 - smooth_step(l, kBlueGreenNm);
  return k == 0 ? red : k == 2 ? blue : 1 - red - blue;
}

// M^-1, M[i][k] the linear sRGB channel i under D65 of block k.
const std::vector<std::vector<double>>& blocks_to_rgb_inverse() {
  static const std::vector<std::vector<double>> inverse = [] {
    std::vector<std::vector<double>> m(3, std::vector<double>(3, 0.0));
    const auto& w = srgb_band_weights_d65();
    for (int b = 0; b < kNumBands; ++b)
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) m[i][k] += w[b][i] * block(k, b);
    invert_matrix(m);  // the blocks' colours are far apart: M is well conditioned
    return m;
  }();
  return inverse;
}

}  // namespace

ThreadDye thread_dye(const std::array<double, 3>& srgb, double fiber_radius_um,
                     const std::string& field) {
  for (double v : srgb)
    if (!(v >= 0 && v <= 1))
      throw Error("", field, "a thread colour's components must lie in [0, 1]");
  if (!(fiber_radius_um > 0)) throw Error("", field, "the fibre radius must be > 0");
  // The white reflector's colour: the weights summed per channel.
  Rgb white;
  for (const Rgb& w : srgb_band_weights_d65()) white += w;
  const auto& inv = blocks_to_rgb_inverse();
  ThreadDye dye;
  std::array<double, 3> dark{};
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 3; ++i)
      dark[k] += inv[k][i] * white[i] * (1 - srgb_gamma_to_linear(srgb[i]));
    dark[k] = std::clamp(dark[k], 0.0, 1.0);  // in [0, 1] but for rounding (the header)
  }
  const double chord_um = 0.5 * kPi * fiber_radius_um;
  for (int b = 0; b < kNumBands; ++b) {
    double rho = 1;
    for (int k = 0; k < 3; ++k) rho -= dark[k] * block(k, b);
    dye.reflectance[b] = rho;
    // max with +0: white's -ln(1) is -0, which would change the spec's canonical text.
    dye.absorption_per_um[b] =
        std::max(0.0, -std::log(std::max(rho, kThreadMinReflectance)) / chord_um);
  }
  return dye;
}

Spectrum thread_colour_block(int k) {
  Spectrum s{};
  for (int b = 0; b < kNumBands; ++b) s[b] = block(k, b);
  return s;
}

FiberSpec thread_colour_spec(const FiberSpec& base, const std::array<double, 3>& srgb,
                             const std::string& field) {
  const ThreadDye dye = thread_dye(srgb, base.fiber_radius_um, field);
  if (srgb == std::array<double, 3>{1, 1, 1}) return base;  // no dye: the base, named as it is
  FiberSpec s = base;
  for (int b = 0; b < kNumBands; ++b) s.host_absorption_per_um[b] += dye.absorption_per_um[b];
  s.name = base.name + " " + srgb_hex(srgb);
  return s;
}

std::string srgb_hex(const std::array<double, 3>& srgb) {
  char text[8];
  auto byte = [](double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); };
  std::snprintf(text, sizeof text, "#%02x%02x%02x", byte(srgb[0]), byte(srgb[1]), byte(srgb[2]));
  return text;
}

}  // namespace weft
