#include "weft/materials/table_inplane.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {

std::vector<Rgb> inplane_beta(const TableReader& t, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths) {
  if (t.channels() != 3) throw Error("", "channels", "inplane_beta needs an RGB table");
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
      t.eval(wo, wi, f);
      sum += Rgb(f[0], f[1], f[2]);
    }
    out[k] = sum * (kPi / azimuths);
  }
  return out;
}

namespace {

// Spectral values, 33 per entry, as linear sRGB, 3 per entry, unclamped.
std::vector<float> bands_to_rgb_values(const std::vector<float>& bands, OutOfGamut* out_of_gamut) {
  const size_t entries = bands.size() / kNumBands;
  std::vector<float> out(entries * 3);
  for (size_t c = 0; c < entries; ++c) {
    const float* v = &bands[c * kNumBands];
    Rgb rgb = bands_to_linear_srgb([v](int b) { return v[b]; });
    if (out_of_gamut)
      for (int k = 0; k < 3; ++k)
        if (rgb[k] < 0) {
          ++out_of_gamut->components;
          out_of_gamut->largest = std::max(out_of_gamut->largest, -rgb[k]);
        }
    out[c * 3] = static_cast<float>(rgb.r);
    out[c * 3 + 1] = static_cast<float>(rgb.g);
    out[c * 3 + 2] = static_cast<float>(rgb.b);
  }
  return out;
}

}  // namespace

TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& t, OutOfGamut* out_of_gamut) {
  if (t.channels == 3) return t;
  if (t.channels != kNumBands) throw Error("", "channels", "neither RGB nor 33 bands");
  TabulatedBsdfTable o;
  o.resolution = t.resolution;
  o.channels = 3;
  o.kind = t.kind;
  o.metadata = t.metadata;
  o.values = bands_to_rgb_values(t.values, out_of_gamut);
  return o;
}

TableReader table_to_rgb(const TableReader& t, OutOfGamut* out_of_gamut) {
  if (t.channels() == 3) return t;
  std::optional<HalfVectorLobe> sheen;
  if (t.sheen()) {
    sheen = *t.sheen();
    sheen->channels = 3;
    sheen->values = bands_to_rgb_values(t.sheen()->values, out_of_gamut);
  }
  return TableReader(table_to_rgb(t.cells(), out_of_gamut), std::move(sheen));
}

}  // namespace weft
