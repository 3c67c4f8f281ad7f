#include <algorithm>
#include <cmath>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/optimize.h"
#include "weft/exchange/gltf_material.h"
#include "weft/exchange/table_view.h"

namespace weft {
namespace {

struct Pair {
  Vec3 wo, wi;
  Rgb target;
};

// The comparison grid: view and light at the centres of the upper bins of a grid of resolution
// min(R, max_resolution), the table interpolated there (its cell values where the grids agree).
std::vector<Pair> comparison_pairs(const TableView& view, int max_resolution) {
  const auto& table = view.table();
  const DirectionGrid grid{std::min(table.resolution, max_resolution)};
  const int upper = grid.resolution * grid.resolution;
  std::vector<double> f(static_cast<size_t>(view.channels()));
  std::vector<Pair> pairs;
  for (int o = 0; o < upper; ++o)
    for (int i = 0; i < upper; ++i) {
      const Vec3 wo = grid.bin_center(o), wi = grid.bin_center(i);
      table.interpolate(wo, wi, f);
      pairs.push_back({wo, wi, view.rgb(f)});
    }
  return pairs;
}

GltfMaterial material_at(const std::vector<double>& u, double transmission) {
  GltfMaterial m;
  m.base_color = {u[0], u[1], u[2]};
  m.roughness = 0.05 + 0.95 * u[3];
  m.sheen_color = {u[4], u[5], u[6]};
  m.sheen_roughness = 0.07 + 0.93 * u[7];
  m.transmission = transmission;
  return m;
}

// The mean over the upper view bins of the table's transmittance seen from above (light from
// below reaching a view from above, TabulatedBsdfTable::directional_albedo_seen_from), over
// channels, and its share of all the light reaching the view.
std::pair<double, double> mean_transmittance(const TabulatedBsdfTable& table) {
  const int upper = table.resolution * table.resolution;
  double t = 0, share = 0;
  for (int o = 0; o < upper; ++o) {
    const auto a = table.directional_albedo_seen_from(o);
    double tt = 0, rr = 0;
    for (int c = 0; c < table.channels; ++c) {
      tt += a.transmittance[static_cast<size_t>(c)];
      rr += a.reflectance[static_cast<size_t>(c)];
    }
    t += tt / table.channels;
    share += tt + rr > 0 ? tt / (tt + rr) : 0;
  }
  return {t / upper, share / upper};
}

}  // namespace

GltfFit fit_gltf_material(const TabulatedBsdfTable& table, const GltfFitOptions& o) {
  if (o.max_resolution < 1) throw Error("", "max_resolution", "must be at least 1");
  if (!(o.epsilon_per_sr > 0)) throw Error("", "epsilon_per_sr", "must be > 0");
  const TableView view(table, 1);
  const std::vector<Pair> pairs = comparison_pairs(view, o.max_resolution);
  GltfFit fit;
  fit.points = static_cast<int>(pairs.size());
  const auto [transmittance, share] = mean_transmittance(table);
  fit.transmittance = transmittance;
  const double transmission = transmittance > o.transmission_threshold ? share : 0.0;
  const double eps = o.epsilon_per_sr;
  // The sheen albedo depends on one of the 8 parameters: kept while that one stays.
  std::optional<std::pair<double, SheenAlbedo>> albedo;
  const ResidualFunction residuals = [&](const std::vector<double>& u) {
    const GltfMaterial m = material_at(u, transmission);
    if (!albedo || albedo->first != m.sheen_roughness)
      albedo.emplace(m.sheen_roughness, SheenAlbedo(m.sheen_roughness));
    const SheenAlbedo& e = albedo->second;
    std::vector<double> r;
    r.reserve(pairs.size() * 3);
    for (const auto& p : pairs) {
      const Rgb f = gltf_brdf(m, e, p.wo, p.wi);
      for (int c = 0; c < 3; ++c) r.push_back(std::log((f[c] + eps) / (p.target[c] + eps)));
    }
    return r;
  };
  // Start: the base colour from the table's mean reflectance (pi f), a rough base, a mild sheen.
  Rgb mean;
  for (const auto& p : pairs) mean += p.target;
  std::vector<double> u0(8);
  for (int c = 0; c < 3; ++c)
    u0[static_cast<size_t>(c)] =
        std::clamp(mean[c] * kPi / static_cast<double>(pairs.size()), 0.0, 1.0);
  u0[3] = 0.7;
  for (int c = 4; c < 7; ++c) u0[static_cast<size_t>(c)] = 0.2;
  u0[7] = 0.5;
  OptimizeOptions opt;
  opt.max_evaluations = o.max_evaluations;
  opt.tolerance = 1e-6;
  const OptimizeResult best = levenberg_marquardt(residuals, u0, opt);
  fit.material = material_at(best.u, transmission);
  fit.rms_log = best.objective;
  fit.rms_log_start = best.objective_start;
  fit.evaluations = best.evaluations;
  return fit;
}

}  // namespace weft
