#include "weft/materials/colour_reading.h"

#include <cmath>

#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {

Rgb nbrdf_d8_reflectance(const NbrdfNetwork& network, int n) {
  const double t = kD8IncidenceDeg * kPi / 180;
  const Vec3 wi{std::sin(t), 0, std::cos(t)};
  Rgb sum;
  for (int i = 0; i < n; ++i) {
    const double sin2 = (i + 0.5) / n, sin_theta = std::sqrt(sin2), cos_theta = std::sqrt(1 - sin2);
    for (int j = 0; j < n; ++j) {
      const double phi = 2 * kPi * (j + 0.5) / n;
      sum +=
          network.eval_upper({sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta}, wi);
    }
  }
  // Cells of equal cos-weighted solid angle pi / n^2: the integral of f cos is pi times the mean.
  return sum * (kPi / (static_cast<double>(n) * n));
}

std::vector<double> table_d8_reflectance(const TabulatedBsdfTable& table) {
  const auto a = table.directional_albedo(table.grid().bin_of({0, 0, 1}));
  return {a.reflectance.begin(), a.reflectance.begin() + table.channels};
}

ColourTarget read_colour_target(const std::string& spec, const std::string& field) {
  if (spec.rfind("measured:", 0) == 0) {
    const std::string name = spec.substr(9);
    const NbrdfNetwork net = NbrdfNetwork::load(find_measured_nbrdf(name));
    return linear_srgb_target(nbrdf_d8_reflectance(net), spec);
  }
  if (spec.rfind("table:", 0) != 0) return parse_colour_target(spec, field);
  const std::string file = spec.substr(6);
  const TabulatedBsdfTable table = TabulatedBsdfTable::read_exr(file);
  const std::vector<double> r = table_d8_reflectance(table);
  if (table.channels == 3) return linear_srgb_target({r[0], r[1], r[2]}, spec);
  if (table.channels != kNumBands)
    throw Error(file, field, "a colour is read from an RGB or a spectral (33-band) table");
  ColourTarget t;
  t.spec = spec;
  t.kind = ColourTarget::Kind::kSpectrum;
  t.observer = Observer::kCie1931TwoDegree;
  t.file = file;
  t.reflectance.emplace();
  for (int b = 0; b < kNumBands; ++b) (*t.reflectance)[b] = r[b];
  t.lab = reflectance_to_lab(*t.reflectance, t.observer);
  return t;
}

}  // namespace weft
