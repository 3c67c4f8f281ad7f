#include "weft/core/spectrum.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "weft/core/colorimetry.h"
#include "weft/core/error.h"

namespace weft {
namespace detail {
extern const char* const kCieCmfCsv;
extern const char* const kCieD65Csv;
extern const char* const kCieCmf10Csv;
}  // namespace detail

namespace {

// wavelength (nm, integer) -> columns. The first line is a header.
std::map<int, std::vector<double>> parse_csv(const char* text, size_t columns, const char* name) {
  std::map<int, std::vector<double>> rows;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    if (line.empty() || line == "\r") continue;
    std::istringstream ls(line);
    std::string cell;
    std::vector<double> values;
    while (std::getline(ls, cell, ',')) values.push_back(std::stod(cell));
    if (values.size() != columns + 1) throw Error(name, "", "malformed CIE row: " + line);
    const int nm = static_cast<int>(std::lround(values[0]));
    values.erase(values.begin());
    rows[nm] = std::move(values);
  }
  return rows;
}

double band_average(const std::map<int, std::vector<double>>& rows, int band, size_t column) {
  return band_mean_1nm(band, [&](int nm) { return rows.at(nm)[column]; });
}

std::array<Xyz, kNumBands> cmf_band_table(const char* csv, const char* name) {
  const auto rows = parse_csv(csv, 3, name);
  std::array<Xyz, kNumBands> t{};
  for (int b = 0; b < kNumBands; ++b)
    t[b] = {band_average(rows, b, 0), band_average(rows, b, 1), band_average(rows, b, 2)};
  return t;
}

}  // namespace

double band_mean_1nm(int band, const std::function<double(int nm)>& value_at_nm) {
  const int centre = static_cast<int>(band_wavelength_nm(band));
  double sum = 0, weight = 0;
  for (int nm = centre - 5; nm <= centre + 5; ++nm) {
    const double w = (nm == centre - 5 || nm == centre + 5) ? 0.5 : 1.0;
    sum += w * value_at_nm(nm);
    weight += w;
  }
  return sum / weight;
}

const std::array<Xyz, kNumBands>& cie_cmf_bands() {
  return cie_cmf_bands(Observer::kCie1931TwoDegree);
}

const std::array<Xyz, kNumBands>& cie_cmf_bands(Observer observer) {
  static const std::array<Xyz, kNumBands> two =
      cmf_band_table(detail::kCieCmfCsv, "CIE_xyz_1931_2deg_360-830.csv");
  static const std::array<Xyz, kNumBands> ten =
      cmf_band_table(detail::kCieCmf10Csv, "CIE_xyz_1964_10deg_360-830.csv");
  return observer == Observer::kCie1964TenDegree ? ten : two;
}

const Spectrum& d65_bands() {
  static const Spectrum table = [] {
    const auto rows = parse_csv(detail::kCieD65Csv, 1, "CIE_std_illum_D65.csv");
    Spectrum t{};
    for (int b = 0; b < kNumBands; ++b) t[b] = band_average(rows, b, 0);
    return t;
  }();
  return table;
}

Xyz reflectance_to_xyz_d65(const Spectrum& reflectance) {
  return reflectance_to_xyz_d65(reflectance, Observer::kCie1931TwoDegree);
}

Xyz reflectance_to_xyz_d65(const Spectrum& reflectance, Observer observer) {
  const auto& cmf = cie_cmf_bands(observer);
  const auto& d65 = d65_bands();
  double x = 0, y = 0, z = 0, norm = 0;
  for (int b = 0; b < kNumBands; ++b) {
    const double e = d65[b];
    x += reflectance[b] * e * cmf[b].x;
    y += reflectance[b] * e * cmf[b].y;
    z += reflectance[b] * e * cmf[b].z;
    norm += e * cmf[b].y;
  }
  return {x / norm, y / norm, z / norm};
}

Rgb xyz_to_linear_srgb(const Xyz& c) {
  // IEC 61966-2-1 (sRGB) XYZ -> linear RGB, D65 white.
  return {3.2406 * c.x - 1.5372 * c.y - 0.4986 * c.z, -0.9689 * c.x + 1.8758 * c.y + 0.0415 * c.z,
          0.0557 * c.x - 0.2040 * c.y + 1.0570 * c.z};
}

double linear_to_srgb_gamma(double v) {
  if (v <= 0.0031308) return 12.92 * v;
  return 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

Hsv rgb_to_hsv(const Rgb& c) {
  const double mx = std::max({c.r, c.g, c.b});
  const double mn = std::min({c.r, c.g, c.b});
  const double delta = mx - mn;
  Hsv out;
  out.v = mx;
  out.s = mx > 0 ? delta / mx : 0;
  if (delta <= 0) return out;
  double h;
  if (mx == c.r)
    h = (c.g - c.b) / delta;
  else if (mx == c.g)
    h = 2 + (c.b - c.r) / delta;
  else
    h = 4 + (c.r - c.g) / delta;
  h /= 6;
  if (h < 0) h += 1;
  out.h = h;
  return out;
}

const std::array<Rgb, kNumBands>& srgb_band_weights_d65() {
  static const std::array<Rgb, kNumBands> table = [] {
    std::array<Rgb, kNumBands> w{};
    for (int b = 0; b < kNumBands; ++b) {
      Spectrum delta{};
      delta[b] = 1;
      w[b] = xyz_to_linear_srgb(reflectance_to_xyz_d65(delta));
    }
    return w;
  }();
  return table;
}

}  // namespace weft
