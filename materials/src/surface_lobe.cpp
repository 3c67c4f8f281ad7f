#include "weft/materials/surface_lobe.h"

#include <cmath>
#include <cstdio>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/materials/cook_torrance.h"

namespace weft {
namespace {

constexpr const char* kDistribution = "surface_lobe_distribution";
constexpr const char* kAlpha = "surface_lobe_alpha";
constexpr const char* kIor = "surface_lobe_ior";
constexpr const char* kCookTorrance = "cook-torrance";
// The quadrature of cell_averages: wi directions per bin side, lobe draws per lattice side.
constexpr int kWiSide = 16, kWoSide = 24;

CookTorranceBsdf lobe_of(const SurfaceLobe& l, int channel) {
  return CookTorranceBsdf{l.distribution, l.ior[static_cast<size_t>(channel)], Rgb(1.0)};
}

}  // namespace

SurfaceLobe::DistinctIndices SurfaceLobe::distinct_indices() const {
  DistinctIndices g;
  for (double n : ior) {
    size_t k = 0;
    while (k < g.ior.size() && g.ior[k] != n) ++k;
    if (k == g.ior.size()) g.ior.push_back(n);
    g.of_channel.push_back(static_cast<int>(k));
  }
  return g;
}

double SurfaceLobe::eval(const Vec3& wo, const Vec3& wi, int channel) const {
  return lobe_of(*this, channel).eval_upper(wo, wi);
}

void SurfaceLobe::eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const {
  double last_ior = 0, last = 0;
  for (int c = 0; c < channels(); ++c) {
    const double n = ior[static_cast<size_t>(c)];
    if (c == 0 || n != last_ior) last = eval(wo, wi, c), last_ior = n;
    out[static_cast<size_t>(c)] = last;
  }
}

std::optional<Vec3> SurfaceLobe::sample(const Vec3& wi, Vec2 u, double* pdf) const {
  if (!(wi.z > 0)) return std::nullopt;
  const Vec3 h = distribution.sample_normal(wi, u);
  const double wi_h = dot(wi, h);
  if (!(wi_h > 0)) return std::nullopt;
  const Vec3 wo = normalize(reflect(wi, h));
  if (!(wo.z > 0)) return std::nullopt;
  *pdf = this->pdf(wi, wo);
  if (!(*pdf > 0)) return std::nullopt;
  return wo;
}

double SurfaceLobe::pdf(const Vec3& wi, const Vec3& wo) const {
  // The visible-normal draw for wi is CookTorranceBsdf's for its first direction.
  return CookTorranceBsdf{distribution, 1.5, Rgb(1.0)}.pdf_upper(wi, wo);
}

std::vector<double> SurfaceLobe::cell_averages(const DirectionGrid& grid, int threads) const {
  const int nc = channels();
  const size_t bins = static_cast<size_t>(grid.bins());
  std::vector<double> out(bins * bins * static_cast<size_t>(nc), 0.0);
  const auto d = grid.cosine_weighted_areas();
  const DistinctIndices groups = distinct_indices();
  const size_t ng = groups.ior.size();
  const int upper = grid.resolution * grid.resolution;
  parallel_for(static_cast<uint64_t>(upper), threads, [&](uint64_t task) {
    const int i = static_cast<int>(task);
    std::vector<double> row(bins * ng, 0.0);  // per wo bin and index: sum cos_i f cos_o / pdf
    double cos_sum = 0;
    for (int k = 0; k < kWiSide * kWiSide; ++k) {
      const Vec3 wi = DirectionGrid::to_direction(
          grid.chart_point(i, (k % kWiSide + 0.5) / kWiSide, (k / kWiSide + 0.5) / kWiSide));
      if (!(wi.z > 0)) continue;
      cos_sum += wi.z;
      // A Cranley-Patterson shift of the lattice per wi (golden-ratio steps), against aliasing.
      const double sx = std::fmod(0.6180339887498949 * (k + 1), 1.0);
      const double sy = std::fmod(0.7548776662466927 * (k + 1), 1.0);
      for (int j = 0; j < kWoSide * kWoSide; ++j) {
        const Vec2 u{std::fmod((j % kWoSide + 0.5) / kWoSide + sx, 1.0),
                     std::fmod((j / kWoSide + 0.5) / kWoSide + sy, 1.0)};
        double p = 0;
        const auto wo = sample(wi, u, &p);
        if (!wo) continue;
        const size_t o = static_cast<size_t>(grid.bin_of(*wo));
        for (size_t g = 0; g < ng; ++g) {
          const double f =
              CookTorranceBsdf{distribution, groups.ior[g], Rgb(1.0)}.eval_upper(*wo, wi);
          row[o * ng + g] += wi.z * f * wo->z / p;
        }
      }
    }
    if (!(cos_sum > 0)) return;
    const double norm = 1.0 / (cos_sum * kWoSide * kWoSide);
    for (size_t o = 0; o < bins; ++o)
      for (int c = 0; c < nc; ++c)
        out[(static_cast<size_t>(i) * bins + o) * nc + static_cast<size_t>(c)] =
            row[o * ng + static_cast<size_t>(groups.of_channel[static_cast<size_t>(c)])] * norm /
            d[o];
  });
  return out;
}

bool SurfaceLobe::is_attribute(const std::string& name) {
  return name == kKindAttribute || name == kDistribution || name == kAlpha || name == kIor;
}

std::map<std::string, std::string> SurfaceLobe::attributes() const {
  std::string list;
  for (size_t c = 0; c < ior.size(); ++c) list += (c ? "," : "") + exact_number(ior[c]);
  return {{kKindAttribute, kCookTorrance},
          {kDistribution, microfacet_model_name(distribution.model)},
          {kAlpha, exact_number(distribution.alpha)},
          {kIor, list}};
}

std::optional<SurfaceLobe> SurfaceLobe::from_attributes(const std::map<std::string, std::string>& a,
                                                        int channels, const std::string& file) {
  const auto kind = a.find(kKindAttribute);
  if (kind == a.end()) {
    for (const auto& [key, value] : a)
      if (is_attribute(key)) throw Error(file, key, "given without \"surface_lobe\"");
    return std::nullopt;
  }
  if (kind->second != kCookTorrance)
    throw Error(file, kKindAttribute, "must be \"cook-torrance\", got \"" + kind->second + "\"");
  auto get = [&](const char* key) {
    const auto it = a.find(key);
    if (it == a.end()) throw Error(file, key, "is required with \"surface_lobe\"");
    return it->second;
  };
  SurfaceLobe lobe;
  const std::string dist = get(kDistribution);
  if (dist != "ggx" && dist != "beckmann")
    throw Error(file, kDistribution, "must be \"ggx\" or \"beckmann\", got \"" + dist + "\"");
  lobe.distribution.model = dist == "ggx" ? MicrofacetModel::kGgx : MicrofacetModel::kBeckmann;
  const auto alpha = finite_number(get(kAlpha));
  if (!alpha) throw Error(file, kAlpha, "is not a number: \"" + get(kAlpha) + "\"");
  lobe.distribution.alpha = *alpha;
  const std::string list = get(kIor);
  // Counted before any is converted: at most the table's channels.
  size_t commas = 0;
  for (char ch : list) commas += ch == ',';
  if (commas + 1 != static_cast<size_t>(channels))
    throw Error(file, kIor,
                "holds " + std::to_string(commas + 1) + " indices, expected one per channel (" +
                    std::to_string(channels) + ")");
  for (size_t start = 0; start <= list.size();) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const auto n = finite_number(list.substr(start, end - start));
    if (!n)
      throw Error(file, kIor, "holds \"" + list.substr(start, end - start) + "\", not a number");
    lobe.ior.push_back(*n);
    start = end + 1;
  }
  lobe.validate(channels, file);
  return lobe;
}

void SurfaceLobe::validate(int channels, const std::string& file) const {
  if (!(distribution.alpha >= 1e-3 && distribution.alpha <= 2))
    throw Error(file, kAlpha, "must lie in [0.001, 2], got " + exact_number(distribution.alpha));
  if (static_cast<int>(ior.size()) != channels)
    throw Error(
        file, kIor,
        "holds " + std::to_string(ior.size()) + " indices, expected " + std::to_string(channels));
  for (double n : ior)
    if (!(n >= 1 && n <= 4))
      throw Error(file, kIor, "index " + exact_number(n) + " is outside [1, 4]");
}

}  // namespace weft
