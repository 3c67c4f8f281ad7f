#include "weft/materials/weave_modulation.h"

#include <cmath>

#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// The two cells whose centres surround s (in cells; centre of cell i at i + 0.5) on a ring of n,
// and the weight of the second.
struct RingPair {
  uint32_t a = 0, b = 0;
  double t = 0;
};
RingPair ring_pair(double s, int n) {
  const double x = s - 0.5;
  const double f = std::floor(x);
  const double wrapped = f - n * std::floor(f / n);  // in [0, n)
  RingPair r;
  r.a = static_cast<uint32_t>(wrapped) % static_cast<uint32_t>(n);
  r.b = (r.a + 1) % static_cast<uint32_t>(n);
  r.t = x - f;
  return r;
}

// A spectral weave's RGB: per channel the band mean weighted by the positive D65 sRGB weights.
std::vector<float> reduce_bands(const WeaveTable& t) {
  if (t.channels == 3) return t.modulation;
  const auto& w = srgb_band_weights_d65();
  Rgb total;
  for (int b = 0; b < kNumBands; ++b)
    for (int c = 0; c < 3; ++c) total[c] += std::max(0.0, w[b][c]);
  const size_t cells = t.modulation.size() / kNumBands;
  std::vector<float> out(cells * 3);
  for (size_t k = 0; k < cells; ++k) {
    Rgb sum;
    for (int b = 0; b < kNumBands; ++b)
      for (int c = 0; c < 3; ++c)
        sum[c] += std::max(0.0, w[b][c]) * double(t.modulation[k * kNumBands + b]);
    for (int c = 0; c < 3; ++c) out[3 * k + c] = static_cast<float>(sum[c] / total[c]);
  }
  return out;
}

}  // namespace

WeaveModulation::WeaveModulation(WeaveTable table)
    : table_(std::move(table)), grid_{table_.resolution}, rgb_(reduce_bands(table_)) {
  if (table_.channels == kNumBands) bands_ = std::move(table_.modulation);
  table_.modulation.clear();  // one copy of the values: rgb_ and bands_
}

WeavePoint WeaveModulation::locate(Vec2 uv, double uv_metres) const {
  const RingPair u =
      ring_pair(uv.x * uv_metres / table_.repeat_u_m * table_.positions_u, table_.positions_u);
  const RingPair v =
      ring_pair(uv.y * uv_metres / table_.repeat_v_m * table_.positions_v, table_.positions_v);
  const auto pu = static_cast<uint32_t>(table_.positions_u);
  WeavePoint p;
  p.pos = {v.a * pu + u.a, v.a * pu + u.b, v.b * pu + u.a, v.b * pu + u.b};
  p.weight = {(1 - u.t) * (1 - v.t), u.t * (1 - v.t), (1 - u.t) * v.t, u.t * v.t};
  return p;
}

template <class Out>
void WeaveModulation::blend(const std::vector<float>& values, int channels, const WeavePoint& at,
                            const Vec3& wo, const Vec3& wi, Out& out) const {
  const size_t n = static_cast<size_t>(grid_.bins()), nc = static_cast<size_t>(channels);
  for_each_interpolated_cell(grid_, wo, wi, [&](int i, int o, double w) {
    for (int k = 0; k < 4; ++k) {
      if (at.weight[k] == 0) continue;
      const double wk = w * at.weight[k];
      const float* m = &values[((at.pos[k] * n + size_t(i)) * n + size_t(o)) * nc];
      for (size_t c = 0; c < nc; ++c) out[c] += wk * double(m[c]);
    }
  });
}

Rgb WeaveModulation::rgb(const WeavePoint& at, const Vec3& wo, const Vec3& wi) const {
  Rgb out;
  blend(rgb_, 3, at, wo, wi, out);
  return out;
}

void WeaveModulation::bands(const WeavePoint& at, const Vec3& wo, const Vec3& wi,
                            Spectrum& out) const {
  out.fill(0.0);
  blend(bands_, kNumBands, at, wo, wi, out);
}

}  // namespace weft
