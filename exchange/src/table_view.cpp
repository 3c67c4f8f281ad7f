#include "weft/exchange/table_view.h"

#include <cmath>

#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {

TableView::TableView(const TabulatedBsdfTable& table, int azimuths)
    : table_(table), reader_(table) {
  if (azimuths < 1) throw Error("", "azimuths", "needs at least one rotation");
  for (int k = 0; k < azimuths; ++k) {
    const double phi = 2 * kPi * k / azimuths;
    cos_.push_back(std::cos(phi));
    sin_.push_back(std::sin(phi));
  }
  if (spectral()) {
    for (int b = 0; b < kNumBands; ++b) {
      Spectrum unit{};
      unit[static_cast<size_t>(b)] = 1;
      y_weights_.push_back(reflectance_to_xyz_d65(unit).y);
    }
  } else {
    y_weights_ = {0.2126, 0.7152, 0.0722};
  }
}

void TableView::isotropic(const Vec3& wo, const Vec3& wi, std::span<double> out) const {
  std::vector<double> one(static_cast<size_t>(channels()));
  for (double& v : out) v = 0;
  for (size_t k = 0; k < cos_.size(); ++k) {
    const double c = cos_[k], s = sin_[k];
    const Vec3 ro{c * wo.x - s * wo.y, s * wo.x + c * wo.y, wo.z};
    const Vec3 ri{c * wi.x - s * wi.y, s * wi.x + c * wi.y, wi.z};
    reader_.eval(ro, ri, one);
    for (size_t j = 0; j < out.size(); ++j) out[j] += one[j];
  }
  for (double& v : out) v /= static_cast<double>(cos_.size());
}

double TableView::luminance(std::span<const double> values) const {
  double y = 0;
  for (size_t j = 0; j < values.size(); ++j) y += y_weights_[j] * values[j];
  return y;
}

Rgb TableView::rgb(std::span<const double> values, GamutClip* clip) const {
  if (!spectral()) return {values[0], values[1], values[2]};
  Rgb c = bands_to_linear_srgb([&](int b) { return values[static_cast<size_t>(b)]; });
  GamutClip local;
  (clip ? *clip : local).clip(c);
  return c;
}

}  // namespace weft
