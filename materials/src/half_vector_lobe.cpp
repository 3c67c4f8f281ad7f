#include "weft/materials/half_vector_lobe.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/materials/fresnel.h"

namespace weft {
namespace {

constexpr const char* kHResolution = "sheen_h_resolution";
constexpr const char* kWindow = "sheen_window";
constexpr const char* kFresnelIor = "sheen_fresnel_ior";
constexpr const char* kLightResolution = "sheen_light_resolution";
constexpr const char* kWindowKind = "half-vector window";
// The quadrature of cell_averages: wi directions per table bin side (a multiple of every light
// factor, so that each light bin has its share of them), half vectors per window bin side.
constexpr int kQuadWiSide = 16, kQuadHSide = 3;
static_assert(kQuadWiSide % HalfVectorLobe::kMaxLightFactor == 0);

// The first row and column of the window in the upper square of DirectionGrid{h_resolution}.
int window_origin(const HalfVectorLobe& l) {
  return (l.h_resolution - l.window) / 2;
}

// The Fresnel index: 0 (none) or in (1, kMaxFresnelIor].
void check_fresnel_ior(double ior, const std::string& file) {
  if (!(ior == 0 || (ior > 1 && ior <= HalfVectorLobe::kMaxFresnelIor)))
    throw Error(file, kFresnelIor,
                "must be 0 (none) or in (1, " + ParamReader::fmt(HalfVectorLobe::kMaxFresnelIor) +
                    "], got " + ParamReader::fmt(ior));
}

}  // namespace

HalfVectorLobe HalfVectorLobe::zeros(int resolution, int h_resolution, int window, int channels,
                                     int light_resolution) {
  check_shape(h_resolution, window, "", kHResolution, kWindow);
  if (light_resolution == 0) light_resolution = resolution;
  check_light_resolution(resolution, light_resolution, "", kLightResolution);
  HalfVectorLobe l;
  l.resolution = resolution, l.h_resolution = h_resolution, l.window = window;
  l.light_resolution = light_resolution;
  l.channels = channels;
  l.values.assign(
      static_cast<size_t>(l.light_grid().bins()) * l.window_bins() * static_cast<size_t>(channels),
      0.0f);
  return l;
}

size_t HalfVectorLobe::slot(int light_bin) const {
  const int m = light_factor();
  if (m == 1) return static_cast<size_t>(light_bin);
  const int rl = light_resolution, per_square = rl * rl;
  const int hemisphere = light_bin / per_square, y = light_bin % per_square / rl,
            x = light_bin % rl;
  const int cell = hemisphere * resolution * resolution + y / m * resolution + x / m;
  return static_cast<size_t>(cell) * static_cast<size_t>(m * m) +
         static_cast<size_t>(y % m * m + x % m);
}

int HalfVectorLobe::light_bin_at(size_t s) const {
  const int m = light_factor();
  const int cell = static_cast<int>(s / static_cast<size_t>(m * m));
  const int sub = static_cast<int>(s % static_cast<size_t>(m * m));
  // The chart's rows run through both hemispheres (DirectionGrid::chart_point).
  const int row = cell / resolution, x = cell % resolution;
  return (row * m + sub / m) * light_resolution + x * m + sub % m;
}

int HalfVectorLobe::window_bin_of(const Vec3& h) const {
  const DirectionGrid g{h_resolution};
  const int bin = g.bin_of({h.x, h.y, std::abs(h.z)});
  const int row = bin / h_resolution - window_origin(*this);
  const int col = bin % h_resolution - window_origin(*this);
  if (row < 0 || col < 0 || row >= window || col >= window) return -1;
  return row * window + col;
}

double HalfVectorLobe::window_bin_solid_angle() const {
  return DirectionGrid{h_resolution}.bin_solid_angle();
}

Vec3 HalfVectorLobe::window_point(int k, double fx, double fy) const {
  const int o = window_origin(*this);
  const int bin = (k / window + o) * h_resolution + k % window + o;
  return DirectionGrid::to_direction(DirectionGrid{h_resolution}.chart_point(bin, fx, fy));
}

double HalfVectorLobe::value_scale(double wi_dot_h) const {
  return fresnel_ior > 0 ? fresnel_dielectric(std::abs(wi_dot_h), 1.0, fresnel_ior) : 1.0;
}

void HalfVectorLobe::eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const {
  std::fill(out.begin(), out.end(), 0.0);
  if (!(wi.z * wo.z > 0)) return;  // reflection only, neither direction on the horizon
  const Vec3 sum = wi + wo;
  const double len = length(sum);
  if (!(len > 0)) return;
  const int k = window_bin_of(sum / len);
  if (k < 0) return;
  const DirectionGrid::Footprint fp = light_grid().bilinear(DirectionGrid::to_chart(wi));
  const double scale = value_scale(dot(wi, sum) / len) / (4 * std::abs(wi.z) * std::abs(wo.z));
  for (int j = 0; j < 4; ++j) {
    if (fp.weight[j] == 0) continue;
    for (int c = 0; c < channels; ++c)
      out[static_cast<size_t>(c)] += fp.weight[j] * values[index(fp.bin[j], k, c)] * scale;
  }
}

namespace {

// The quadrature's half vectors (window bin k's kQuadHSide^2 points), the same for every wi.
std::vector<Vec3> quadrature_half_vectors(const HalfVectorLobe& l) {
  std::vector<Vec3> hs;
  for (int k = 0; k < l.window_bins(); ++k)
    for (int j = 0; j < kQuadHSide * kQuadHSide; ++j)
      hs.push_back(l.window_point(k, (j % kQuadHSide + 0.5) / kQuadHSide,
                                  (j / kQuadHSide + 0.5) / kQuadHSide));
  return hs;
}

// The quadrature's wi in light bin a (point i) and its chart position.
Vec2 quadrature_chart(const DirectionGrid& grid, int a, int i) {
  return grid.chart_point(a, (i % kQuadWiSide + 0.5) / kQuadWiSide,
                          (i / kQuadWiSide + 0.5) / kQuadWiSide);
}

// For h of the window (upper) and wi: h on wi's side, wi . h, and wo = reflect(wi, h); false
// when wo does not leave on wi's side.
bool reflect_about(const Vec3& wi, const Vec3& window_h, Vec3& wo, double& wi_h) {
  const Vec3 h = wi.z < 0 ? Vec3{window_h.x, window_h.y, -window_h.z} : window_h;
  wi_h = dot(wi, h);
  wo = 2 * wi_h * h - wi;
  return wi_h > 0 && wo.z * wi.z > 0;
}

}  // namespace

std::vector<double> HalfVectorLobe::mean_projections(int threads) const {
  const DirectionGrid grid = light_grid();
  const size_t nk = static_cast<size_t>(window_bins());
  std::vector<double> out(static_cast<size_t>(grid.bins()) * nk, 0.0);
  const std::vector<Vec3> hs = quadrature_half_vectors(*this);
  const int side = kQuadWiSide / light_factor();  // a light bin's share of a table bin's points
  const double n = side * side * kQuadHSide * kQuadHSide;
  parallel_for(static_cast<uint64_t>(grid.bins()), threads, [&](uint64_t task) {
    const int a = static_cast<int>(task);
    const size_t at = slot(a) * nk;
    for (int i = 0; i < side * side; ++i) {
      const Vec3 wi = DirectionGrid::to_direction(
          grid.chart_point(a, (i % side + 0.5) / side, (i / side + 0.5) / side));
      Vec3 wo;
      double wi_h = 0;
      for (size_t m = 0; m < hs.size(); ++m)
        if (reflect_about(wi, hs[m], wo, wi_h))
          out[at + m / (kQuadHSide * kQuadHSide)] += wi_h * value_scale(wi_h) / n;
    }
  });
  return out;
}

std::vector<double> HalfVectorLobe::cell_averages(int threads) const {
  const DirectionGrid grid{resolution};
  const size_t bins = static_cast<size_t>(grid.bins()), nc = static_cast<size_t>(channels);
  std::vector<double> out(bins * bins * nc, 0.0);
  const auto d = grid.cosine_weighted_areas();
  const double omega_wi = grid.bin_solid_angle() / (kQuadWiSide * kQuadWiSide);
  const double omega_h = window_bin_solid_angle() / (kQuadHSide * kQuadHSide);
  const std::vector<Vec3> hs = quadrature_half_vectors(*this);
  const DirectionGrid light = light_grid();
  parallel_for(bins, threads, [&](uint64_t task) {
    const int a = static_cast<int>(task);
    std::vector<double> row(bins * nc, 0.0), q(static_cast<size_t>(window_bins()) * nc);
    for (int i = 0; i < kQuadWiSide * kQuadWiSide; ++i) {
      const Vec2 chart = quadrature_chart(grid, a, i);
      const Vec3 wi = DirectionGrid::to_direction(chart);
      if (wi.z == 0) continue;
      // Q(wi, .) over the window, as eval interpolates it between the light bins.
      const DirectionGrid::Footprint fp = light.bilinear(chart);
      std::fill(q.begin(), q.end(), 0.0);
      for (int j = 0; j < 4; ++j)
        for (size_t k = 0; fp.weight[j] != 0 && k < q.size(); ++k)
          q[k] += fp.weight[j] * values[index(fp.bin[j], 0, 0) + k];
      // f |cos_o| d wo = Q (wi . h) / |cos_i| d h, and the cell average weighs by |cos_i|.
      Vec3 wo;
      double wi_h = 0;
      for (size_t m = 0; m < hs.size(); ++m) {
        if (!reflect_about(wi, hs[m], wo, wi_h)) continue;
        const size_t o = static_cast<size_t>(grid.bin_of(wo));
        const size_t k = m / (kQuadHSide * kQuadHSide);
        const double weight = wi_h * value_scale(wi_h);
        for (size_t c = 0; c < nc; ++c) row[o * nc + c] += q[k * nc + c] * weight;
      }
    }
    for (size_t o = 0; o < bins; ++o)
      for (size_t c = 0; c < nc; ++c)
        out[(static_cast<size_t>(a) * bins + o) * nc + c] =
            row[o * nc + c] * omega_wi * omega_h / (d[task] * d[o]);
  });
  return out;
}

bool HalfVectorLobe::is_attribute(const std::string& name) {
  return name == kKindAttribute || name == kHResolution || name == kWindow || name == kFresnelIor ||
         name == kLightResolution;
}

std::map<std::string, std::string> HalfVectorLobe::attributes() const {
  std::map<std::string, std::string> a{{kKindAttribute, kWindowKind},
                                       {kHResolution, std::to_string(h_resolution)},
                                       {kWindow, std::to_string(window)}};
  if (fresnel_ior > 0) a[kFresnelIor] = exact_number(fresnel_ior);
  if (light_resolution != resolution) a[kLightResolution] = std::to_string(light_resolution);
  return a;
}

std::optional<HalfVectorLobe> HalfVectorLobe::from_attributes(
    const std::map<std::string, std::string>& a, int resolution, int channels,
    const std::string& file, int format_version) {
  const bool newest = format_version == 0;
  const auto kind = a.find(kKindAttribute);
  if (kind == a.end()) {
    for (const auto& [key, value] : a)
      if (is_attribute(key)) throw Error(file, key, "given without \"sheen\"");
    return std::nullopt;
  }
  if (kind->second != kWindowKind)
    throw Error(file, kKindAttribute,
                std::string("must be \"") + kWindowKind + "\", got \"" + kind->second + "\"");
  auto integer = [&](const char* key) {
    const auto it = a.find(key);
    if (it == a.end()) throw Error(file, key, "is required with \"sheen\"");
    const auto n = finite_number(it->second);
    if (!n || *n != std::floor(*n) || std::abs(*n) > 1e6)
      throw Error(file, key, "is not an integer: \"" + it->second + "\"");
    return static_cast<int>(*n);
  };
  HalfVectorLobe l;
  l.resolution = resolution, l.channels = channels;
  l.h_resolution = integer(kHResolution);
  l.window = integer(kWindow);
  check_shape(l.h_resolution, l.window, file, kHResolution, kWindow);
  l.light_resolution = resolution;
  if ((newest || format_version >= 7) && a.count(kLightResolution)) {
    l.light_resolution = integer(kLightResolution);
    check_light_resolution(resolution, l.light_resolution, file, kLightResolution);
  }
  const auto ior = a.find(kFresnelIor);
  if ((newest || format_version >= 6) && ior != a.end()) {
    const auto n = finite_number(ior->second);
    if (!n) throw Error(file, kFresnelIor, "is not a number: \"" + ior->second + "\"");
    l.fresnel_ior = *n;
    check_fresnel_ior(l.fresnel_ior, file);
  }
  return l;
}

void HalfVectorLobe::check_shape(int h_resolution, int window, const std::string& file,
                                 const std::string& h_field, const std::string& window_field) {
  if (h_resolution < 1 || h_resolution > kMaxHResolution)
    throw Error(file, h_field,
                "the half vectors' resolution must lie in [1, " + std::to_string(kMaxHResolution) +
                    "], got " + std::to_string(h_resolution));
  if (window < 1 || window > h_resolution || (h_resolution - window) % 2)
    throw Error(file, window_field,
                "the window must lie in [1, " + std::to_string(h_resolution) +
                    "], centred on the pole (even if the resolution is, odd if it is odd), got " +
                    std::to_string(window));
}

void HalfVectorLobe::check_light_resolution(int resolution, int light_resolution,
                                            const std::string& file, const std::string& field) {
  for (int m = 1; m <= kMaxLightFactor; m *= 2)
    if (light_resolution == m * resolution) return;
  throw Error(file, field,
              "the light bins nest in the table's: must be " + std::to_string(resolution) + ", " +
                  std::to_string(2 * resolution) + " or " + std::to_string(4 * resolution) +
                  " at resolution " + std::to_string(resolution) + ", got " +
                  std::to_string(light_resolution));
}

void HalfVectorLobe::validate(int table_resolution, int table_channels,
                              const std::string& file) const {
  check_shape(h_resolution, window, file, kHResolution, kWindow);
  check_fresnel_ior(fresnel_ior, file);
  if (resolution != table_resolution || channels != table_channels)
    throw Error(file, kKindAttribute, "does not match the table's resolution and channels");
  check_light_resolution(resolution, light_resolution, file, kLightResolution);
  const size_t expected =
      static_cast<size_t>(light_grid().bins()) * window_bins() * static_cast<size_t>(channels);
  if (values.size() != expected)
    throw Error(
        file, kKindAttribute,
        "holds " + std::to_string(values.size()) + " values, expected " + std::to_string(expected));
  for (size_t k = 0; k < values.size(); ++k)
    if (!(std::isfinite(values[k]) && values[k] >= 0))
      throw Error(file, "sheen values[" + std::to_string(k) + "]",
                  "must be finite and >= 0, got " + std::to_string(values[k]));
}

}  // namespace weft
