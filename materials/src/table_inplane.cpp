#include "weft/materials/table_inplane.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {

std::vector<Rgb> inplane_beta(const TabulatedBsdfTable& t, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths) {
  if (t.channels != 3) throw Error("", "channels", "inplane_beta needs an RGB table");
  if (azimuths < 1) throw Error("", "azimuths", "must be >= 1");
  std::vector<Rgb> out(views_deg.size());
  std::array<double, 3> f{};
  const double ti = deg_to_rad(theta_i_deg);
  for (size_t k = 0; k < views_deg.size(); ++k) {
    const double v = deg_to_rad(views_deg[k]);
    Rgb sum;
    for (int a = 0; a < azimuths; ++a) {
      const double phi = 2 * kPi * a / azimuths;
      const Vec3 wi{std::sin(ti) * std::cos(phi), std::sin(ti) * std::sin(phi), std::cos(ti)};
      const Vec3 wo{-std::sin(v) * std::cos(phi), -std::sin(v) * std::sin(phi), std::cos(v)};
      t.interpolate(wo, wi, f);
      sum += Rgb(f[0], f[1], f[2]);
    }
    out[k] = sum * (kPi / azimuths);
  }
  return out;
}

TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& t, OutOfGamut* out_of_gamut) {
  if (t.channels == 3) return t;
  if (t.channels != kNumBands) throw Error("", "channels", "neither RGB nor 33 bands");
  TabulatedBsdfTable o;
  o.resolution = t.resolution;
  o.channels = 3;
  o.kind = t.kind;
  o.metadata = t.metadata;
  const size_t cells = t.values.size() / kNumBands;
  o.values.resize(cells * 3);
  for (size_t c = 0; c < cells; ++c) {
    const float* v = &t.values[c * kNumBands];
    Rgb rgb = bands_to_linear_srgb([v](int b) { return v[b]; });
    if (out_of_gamut)
      for (int k = 0; k < 3; ++k)
        if (rgb[k] < 0) {
          ++out_of_gamut->components;
          out_of_gamut->largest = std::max(out_of_gamut->largest, -rgb[k]);
        }
    o.values[c * 3] = static_cast<float>(rgb.r);
    o.values[c * 3 + 1] = static_cast<float>(rgb.g);
    o.values[c * 3 + 2] = static_cast<float>(rgb.b);
  }
  return o;
}

}  // namespace weft
