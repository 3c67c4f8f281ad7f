#include "weft/materials/bsdf_table.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <set>
#include <utility>

#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/quadrature.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/core/sphere_mapping.h"

namespace weft {

Vec2 OctahedralGrid::to_square(const Vec3& d) {
  return equal_area_sphere_to_square(d);
}
Vec3 OctahedralGrid::to_direction(Vec2 p) {
  return equal_area_square_to_sphere(p);
}

int OctahedralGrid::bin_of_square(Vec2 p) const {
  const int r = resolution;
  const int x = std::clamp(static_cast<int>(std::floor(p.x * r)), 0, r - 1);
  const int y = std::clamp(static_cast<int>(std::floor(p.y * r)), 0, r - 1);
  return y * r + x;
}

Vec3 OctahedralGrid::bin_center(int bin) const {
  const int x = bin % resolution, y = bin / resolution;
  return to_direction({(x + 0.5) / resolution, (y + 0.5) / resolution});
}

int OctahedralGrid::wrapped_bin(int x, int y) const {
  const int r = resolution;
  // Crossing the edge across 'a' reflects a back inside and mirrors the other coordinate b.
  auto fold = [r](int& a, int& b) {
    if (a >= 0 && a < r) return;
    a = a < 0 ? -a - 1 : 2 * r - 1 - a;
    b = r - 1 - b;
  };
  fold(x, y);
  fold(y, x);
  return y * r + x;
}

OctahedralGrid::Footprint OctahedralGrid::bilinear(Vec2 p) const {
  const double px = p.x * resolution - 0.5, py = p.y * resolution - 0.5;
  const double fx0 = std::floor(px), fy0 = std::floor(py);
  const int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  const double tx = px - fx0, ty = py - fy0;
  Footprint fp;
  fp.bin[0] = wrapped_bin(x0, y0);
  fp.bin[1] = wrapped_bin(x0 + 1, y0);
  fp.bin[2] = wrapped_bin(x0, y0 + 1);
  fp.bin[3] = wrapped_bin(x0 + 1, y0 + 1);
  fp.weight[0] = (1 - tx) * (1 - ty);
  fp.weight[1] = tx * (1 - ty);
  fp.weight[2] = (1 - tx) * ty;
  fp.weight[3] = tx * ty;
  return fp;
}

namespace {

// Integral of |cos theta| over the preimage of [a,b] x [c,d] (0 <= a < b, 0 <= c < d) in the
// octahedral square coordinates u', v' in [-1, 1], where d omega = pi du' dv', above and below
// the horizon. On this map |cos theta| depends on rho = u' + v' only (1 - rho^2 on the upper half,
// 1 - (2 - rho)^2 on the lower), so the integral is one-dimensional: int |cos|(rho) m(rho) d rho
// with m(rho) the length of the cut u' + v' = rho through the rectangle. Both factors are
// polynomial between the breakpoints (the horizon rho = 1 among them, so every piece lies on one
// side), so 3-point Gauss-Legendre per piece is exact.
OctahedralGrid::CosineWeightedArea cos_integral_quadrant_rect(double a, double b, double c,
                                                              double d) {
  double breaks[] = {a + c, a + d, b + c, b + d, 1.0};
  std::sort(std::begin(breaks), std::end(breaks));
  const double lo = a + c, hi = b + d;
  auto m = [&](double rho) { return std::max(0.0, std::min(b, rho - c) - std::max(a, rho - d)); };
  auto abs_cos = [](double rho) { return rho <= 1 ? 1 - rho * rho : 1 - (2 - rho) * (2 - rho); };
  std::vector<double> x, w;
  gauss_legendre(3, x, w);
  OctahedralGrid::CosineWeightedArea out;
  for (int k = 0; k + 1 < 5; ++k) {
    const double p0 = std::clamp(breaks[k], lo, hi), p1 = std::clamp(breaks[k + 1], lo, hi);
    if (!(p1 > p0)) continue;
    const double mid = 0.5 * (p0 + p1), half = 0.5 * (p1 - p0);
    double sum = 0;
    for (int q = 0; q < 3; ++q)
      sum += w[q] * half * abs_cos(mid + half * x[q]) * m(mid + half * x[q]);
    (mid < 1 ? out.upper : out.lower) += kPi * sum;
  }
  return out;
}

}  // namespace

std::vector<OctahedralGrid::CosineWeightedArea> OctahedralGrid::cosine_weighted_areas_by_side()
    const {
  std::vector<CosineWeightedArea> out(static_cast<size_t>(resolution) * resolution);
  for (int iy = 0; iy < resolution; ++iy)
    for (int ix = 0; ix < resolution; ++ix) {
      // The bin in u', v', split at the axes so that each piece lies in one quadrant.
      const double u0 = 2.0 * ix / resolution - 1, u1 = 2.0 * (ix + 1) / resolution - 1;
      const double v0 = 2.0 * iy / resolution - 1, v1 = 2.0 * (iy + 1) / resolution - 1;
      CosineWeightedArea& bin = out[static_cast<size_t>(iy) * resolution + ix];
      for (auto [ua, ub] : {std::pair{u0, std::min(u1, 0.0)}, std::pair{std::max(u0, 0.0), u1}})
        for (auto [va, vb] : {std::pair{v0, std::min(v1, 0.0)}, std::pair{std::max(v0, 0.0), v1}}) {
          if (!(ub > ua) || !(vb > va)) continue;
          // Reflect into the first quadrant.
          const double a = std::min(std::abs(ua), std::abs(ub)),
                       b = std::max(std::abs(ua), std::abs(ub));
          const double c = std::min(std::abs(va), std::abs(vb)),
                       d = std::max(std::abs(va), std::abs(vb));
          const CosineWeightedArea piece = cos_integral_quadrant_rect(a, b, c, d);
          bin.upper += piece.upper;
          bin.lower += piece.lower;
        }
    }
  return out;
}

std::vector<double> OctahedralGrid::cosine_weighted_areas() const {
  const auto by_side = cosine_weighted_areas_by_side();
  std::vector<double> out(by_side.size());
  for (size_t k = 0; k < out.size(); ++k) out[k] = by_side[k].total();
  return out;
}

std::vector<double> TabulatedBsdfTable::averages_from_weighted_sums(
    int resolution, const std::vector<double>& weighted_sums) {
  const OctahedralGrid grid{resolution};
  const size_t cells = static_cast<size_t>(grid.bins());
  if (weighted_sums.size() != cells * cells)
    throw Error("", "weighted_sums",
                "holds " + std::to_string(weighted_sums.size()) + " values, expected " +
                    std::to_string(cells * cells));
  const auto d = grid.cosine_weighted_areas();
  std::vector<double> out(weighted_sums.size());
  for (size_t i = 0; i < cells; ++i)
    for (size_t o = 0; o < cells; ++o)
      out[i * cells + o] = weighted_sums[i * cells + o] / (d[i] * d[o]);
  return out;
}

std::string TabulatedBsdfTable::checksum() const {
  uint64_t h = kFnv1a64Basis;
  for (const float v : values) {
    uint32_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    unsigned char bytes[4];
    for (int k = 0; k < 4; ++k) bytes[k] = static_cast<unsigned char>((bits >> (8 * k)) & 0xffu);
    h = fnv1a64(bytes, 4, h);  // little-endian bytes whatever the host's order
  }
  return hex64(h);
}

std::string TabulatedBsdfTable::bands() const {
  return channels == kNumBands ? std::string(kSpectralBands) : std::string("rgb");
}

std::vector<std::string> TabulatedBsdfTable::channel_names() const {
  if (channels == 3) return {"R", "G", "B"};
  std::vector<std::string> names;
  for (int b = 0; b < channels; ++b) {
    // Appending (rather than "w" + ...) sidesteps GCC 12's false -Wrestrict (PR 105329).
    std::string name(1, 'w');
    name += std::to_string(static_cast<int>(band_wavelength_nm(b)));
    names.push_back(std::move(name));
  }
  return names;
}

namespace {

// Attribute names the format itself uses, or that OpenEXR's header reserves.
const std::set<std::string>& reserved_attribute_names() {
  static const std::set<std::string> names = {"weft_format_version",
                                              "cell_average",
                                              "parameterization",
                                              "resolution",
                                              "bands",
                                              "units",
                                              "kind",
                                              "values_fnv1a64",
                                              "channels",
                                              "compression",
                                              "dataWindow",
                                              "displayWindow",
                                              "lineOrder",
                                              "pixelAspectRatio",
                                              "screenWindowCenter",
                                              "screenWindowWidth",
                                              "tiles",
                                              "type",
                                              "name",
                                              "version",
                                              "chunkCount",
                                              "view"};
  return names;
}

}  // namespace

bool TabulatedBsdfTable::is_reserved_attribute(const std::string& name) {
  return reserved_attribute_names().count(name) > 0;
}

void TabulatedBsdfTable::validate(const std::string& file) const {
  if (resolution < 1 || resolution > kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(kMaxResolution) + "], got " +
                    std::to_string(resolution));
  if (channels != 3 && channels != kNumBands)
    throw Error(file, "bands",
                "need 3 (RGB) or 33 (390..710 nm) channels, got " + std::to_string(channels));
  if (kind != "fiber" && kind != "fabric")
    throw Error(file, "kind", "must be \"fiber\" or \"fabric\", got \"" + kind + "\"");
  const size_t expected =
      static_cast<size_t>(bins()) * static_cast<size_t>(bins()) * static_cast<size_t>(channels);
  if (values.size() != expected)
    throw Error(file, "values",
                "holds " + std::to_string(values.size()) + " numbers, expected " +
                    std::to_string(expected));
  for (const auto& [key, value] : metadata) {
    if (key.empty() || reserved_attribute_names().count(key))
      throw Error(file, "metadata." + key, "name is reserved by the table format");
  }
  for (size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (std::isfinite(v) && v >= 0) continue;
    const size_t c = i % static_cast<size_t>(channels);
    const size_t cell = i / static_cast<size_t>(channels);
    const size_t wo = cell % static_cast<size_t>(bins()), wi = cell / static_cast<size_t>(bins());
    throw Error(file,
                "values[wi " + std::to_string(wi) + "][wo " + std::to_string(wo) + "][" +
                    channel_names()[c] + "]",
                std::isfinite(v) ? "is negative (" + std::to_string(v) + ")" : "is not finite");
  }
}

TabulatedBsdfTable TabulatedBsdfTable::from_function(int resolution, int channels,
                                                     const TableFunction& f, int samples_per_cell,
                                                     uint64_t seed, int threads,
                                                     const ProgressCallback& progress) {
  const std::string who = "TabulatedBsdfTable::from_function";
  if (samples_per_cell < 1) throw Error(who, "samples_per_cell", "must be >= 1");
  TabulatedBsdfTable table;
  table.resolution = resolution;
  table.channels = channels;
  if (resolution < 1 || resolution > kMaxResolution || (channels != 3 && channels != kNumBands)) {
    table.validate(who);  // throws the precise message
  }
  const int n_bins = table.bins();
  table.values.assign(static_cast<size_t>(n_bins) * n_bins * channels, 0.0f);
  const double r = resolution;

  // Rows (wi bins) in chunks, so progress is reported from this thread between chunks.
  const int chunk = std::max(1, n_bins / 64);
  auto row = [&](uint64_t wi_task) {
    const int wi_bin = static_cast<int>(wi_task);
    const int n = samples_per_cell;
    std::vector<double> sum(channels), value(channels);
    std::array<std::vector<int>, 4> perm;
    for (auto& p : perm) p.resize(n);
    for (int wo_bin = 0; wo_bin < n_bins; ++wo_bin) {
      Rng rng(seed, static_cast<uint64_t>(wi_bin), static_cast<uint64_t>(wo_bin));
      // Latin hypercube: each of the 4 square coordinates visits each of its n strata once.
      for (auto& p : perm) {
        std::iota(p.begin(), p.end(), 0);
        for (int i = n - 1; i > 0; --i)
          std::swap(p[i], p[std::min<int>(i, static_cast<int>(rng.uniform() * (i + 1)))]);
      }
      std::fill(sum.begin(), sum.end(), 0.0);
      double weight_sum = 0;
      const int xi = wi_bin % resolution, yi = wi_bin / resolution;
      const int xo = wo_bin % resolution, yo = wo_bin / resolution;
      for (int s = 0; s < n; ++s) {
        const Vec2 pi{(xi + (perm[0][s] + rng.uniform()) / n) / r,
                      (yi + (perm[1][s] + rng.uniform()) / n) / r};
        const Vec2 po{(xo + (perm[2][s] + rng.uniform()) / n) / r,
                      (yo + (perm[3][s] + rng.uniform()) / n) / r};
        const Vec3 wi = OctahedralGrid::to_direction(pi), wo = OctahedralGrid::to_direction(po);
        std::fill(value.begin(), value.end(), 0.0);
        f(wo, wi, value);
        const double w = std::abs(wi.z) * std::abs(wo.z);
        weight_sum += w;
        for (int c = 0; c < channels; ++c) {
          if (!std::isfinite(value[c]) || value[c] < 0)
            throw Error(who, "f",
                        "returned a negative or non-finite value at wo bin " +
                            std::to_string(wo_bin) + ", wi bin " + std::to_string(wi_bin));
          sum[c] += value[c] * w;
        }
      }
      // Every cell has |cos| > 0 almost everywhere, so the weights cannot all vanish.
      for (int c = 0; c < channels; ++c)
        table.values[table.index(wi_bin, wo_bin, c)] =
            static_cast<float>(weight_sum > 0 ? sum[c] / weight_sum : 0.0);
    }
  };
  for (int first = 0; first < n_bins; first += chunk) {
    const int count = std::min(chunk, n_bins - first);
    parallel_for(static_cast<uint64_t>(count), threads,
                 [&](uint64_t i) { row(static_cast<uint64_t>(first) + i); });
    if (!progress({"table", static_cast<uint64_t>(first + count), static_cast<uint64_t>(n_bins)}))
      throw Error(who, "", "cancelled");
  }
  return table;
}

TabulatedBsdfTable::DirectionalAlbedo TabulatedBsdfTable::directional_albedo(int wi_bin) const {
  const OctahedralGrid g = grid();
  if (wi_bin < 0 || wi_bin >= g.bins())
    throw Error(
        "", "wi_bin",
        "must lie in [0, " + std::to_string(g.bins() - 1) + "], got " + std::to_string(wi_bin));
  const auto d = g.cosine_weighted_areas_by_side();
  const auto& di = d[static_cast<size_t>(wi_bin)];
  DirectionalAlbedo out{std::vector<double>(channels, 0.0), std::vector<double>(channels, 0.0)};
  for (int wo = 0; wo < g.bins(); ++wo) {
    const auto& d_o = d[static_cast<size_t>(wo)];
    // The shares of D_i D_o with both directions on one side, and on opposite sides, over D_i.
    const double same = (di.upper * d_o.upper + di.lower * d_o.lower) / di.total();
    const double opposite = (di.upper * d_o.lower + di.lower * d_o.upper) / di.total();
    for (int c = 0; c < channels; ++c) {
      const double f = at(wi_bin, wo, c);
      out.reflectance[c] += f * same;
      out.transmittance[c] += f * opposite;
    }
  }
  return out;
}

}  // namespace weft
