#include <algorithm>
#include <cmath>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/frame.h"
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
// min(R, max_resolution), the table read there as the renderer reads it (TableReader: its cell
// values where the grids agree, plus its sheen when it holds one) and averaged over the view's
// rotations.
std::vector<Pair> comparison_pairs(const TableView& view, int max_resolution) {
  const auto& table = view.table();
  const DirectionGrid grid{std::min(table.resolution, max_resolution)};
  const int upper = grid.resolution * grid.resolution;
  std::vector<double> f(static_cast<size_t>(view.channels()));
  std::vector<Pair> pairs;
  for (int o = 0; o < upper; ++o)
    for (int i = 0; i < upper; ++i) {
      const Vec3 wo = grid.bin_center(o), wi = grid.bin_center(i);
      view.isotropic(wo, wi, f);
      pairs.push_back({wo, wi, view.rgb(f)});
    }
  return pairs;
}

GltfMaterial material_at(const std::vector<double>& u, const GltfMaterial& transmission) {
  GltfMaterial m = transmission;
  m.base_color = {u[0], u[1], u[2]};
  m.roughness = 0.05 + 0.95 * u[3];
  m.sheen_color = {u[4], u[5], u[6]};
  m.sheen_roughness = 0.07 + 0.93 * u[7];
  return m;
}

// What the table transmits towards views from above (light from below), per upper view bin.
struct TableTransmission {
  double mean = 0;   // mean over the bins and channels of the transmittance
  double share = 0;  // mean over the bins of its share of all the light reaching the view
  double peak = 0;   // mean over the bins of pi f(v, -v) / transmittance: 1 for a Lambertian
  std::vector<Vec3> views;
  std::vector<Rgb> albedo;  // linear sRGB
};

// From TabulatedBsdfTable::directional_albedo_seen_from and the straight-through value.
TableTransmission table_transmission(const TableView& view) {
  const TabulatedBsdfTable& table = view.table();
  const DirectionGrid grid = table.grid();
  const int upper = table.resolution * table.resolution;
  TableTransmission t;
  std::vector<double> f(static_cast<size_t>(table.channels));
  int peaks = 0;
  for (int o = 0; o < upper; ++o) {
    const auto a = table.directional_albedo_seen_from(o);
    double tt = 0, rr = 0, straight = 0;
    const Vec3 v = grid.bin_center(o);
    view.reader().eval(v, -v, f);
    for (int c = 0; c < table.channels; ++c) {
      tt += a.transmittance[static_cast<size_t>(c)];
      rr += a.reflectance[static_cast<size_t>(c)];
      straight += f[static_cast<size_t>(c)];
    }
    t.mean += tt / table.channels;
    t.share += tt + rr > 0 ? tt / (tt + rr) : 0;
    if (tt > 0) t.peak += kPi * straight / tt, ++peaks;
    t.views.push_back(v);
    t.albedo.push_back(view.rgb(a.transmittance));
  }
  t.mean /= upper;
  t.share /= upper;
  t.peak = peaks > 0 ? t.peak / peaks : 0;
  return t;
}

// int over the lower hemisphere of the diffuse BTDF of 'm' with factor and colour 1, times
// |cos theta_light|: the material's transmitted albedo per unit colour towards 'v' (midpoint rule
// in (cos theta, phi), 32 x 64 points).
double unit_transmitted_albedo(GltfMaterial m, const SheenAlbedo& e, const Vec3& v) {
  m.diffuse_transmission = 1;
  m.diffuse_transmission_color = Rgb(1.0);
  double sum = 0;
  for (int a = 0; a < 32; ++a)
    for (int b = 0; b < 64; ++b) {
      Vec3 l = spherical_direction(std::acos((a + 0.5) / 32), 2 * kPi * (b + 0.5) / 64);
      l.z = -l.z;
      sum += gltf_btdf(m, e, v, l).r * -l.z;
    }
  return sum / 32 * (2 * kPi / 64);
}

// The diffuse transmission's factor before the reflection fit: the transmitted share of the
// light (which weights the diffuse reflection as the table's split does), raised where the
// colour would have to exceed 1 to carry the table's transmittance (the material's per unit
// colour without sheen, K).
double diffuse_transmission_factor(const TableTransmission& t) {
  const SheenAlbedo none(0.5);
  GltfMaterial plain;
  double k = 0;
  Rgb mean;
  for (size_t j = 0; j < t.views.size(); ++j) {
    k += unit_transmitted_albedo(plain, none, t.views[j]);
    mean += t.albedo[j];
  }
  return std::clamp(std::max(t.share, mean.max_component() / k), 0.0, 1.0);
}

// The diffuse transmission colour by least squares on the transmitted albedo over the view bins
// (per channel, clamped to [0, 1]), and the fit's relative errors.
void fit_transmission_color(const TableTransmission& t, GltfFit& fit) {
  GltfMaterial& m = fit.material;
  const SheenAlbedo e(m.sheen_roughness);
  std::vector<double> k;
  double kk = 0;
  Rgb tk;
  for (size_t j = 0; j < t.views.size(); ++j) {
    k.push_back(m.diffuse_transmission * unit_transmitted_albedo(m, e, t.views[j]));
    kk += k.back() * k.back();
    tk += t.albedo[j] * k.back();
  }
  for (int c = 0; c < 3; ++c) m.diffuse_transmission_color[c] = std::clamp(tk[c] / kk, 0.0, 1.0);
  double sum = 0, worst = 0;
  int n = 0;
  for (size_t j = 0; j < t.views.size(); ++j)
    for (int c = 0; c < 3; ++c) {
      if (!(t.albedo[j][c] > 0)) continue;
      const double rel = m.diffuse_transmission_color[c] * k[j] / t.albedo[j][c] - 1;
      sum += rel * rel, ++n;
      worst = std::max(worst, std::abs(rel));
    }
  fit.transmission_rms_rel = n > 0 ? std::sqrt(sum / n) : 0;
  fit.transmission_max_rel = worst;
}

}  // namespace

GltfFit fit_gltf_material(const TabulatedBsdfTable& table, const GltfFitOptions& o) {
  if (o.max_resolution < 1) throw Error("", "max_resolution", "must be at least 1");
  if (!(o.epsilon_per_sr > 0)) throw Error("", "epsilon_per_sr", "must be > 0");
  if (o.azimuths < 1) throw Error("", "azimuths", "must be at least 1");
  const TableView view(table, o.azimuths);
  const std::vector<Pair> pairs = comparison_pairs(view, o.max_resolution);
  GltfFit fit;
  fit.points = static_cast<int>(pairs.size());
  const TableTransmission t = table_transmission(view);
  fit.transmittance = t.mean;
  fit.transmission_peak = t.peak;
  GltfMaterial transmission;  // the factors, fixed during the reflection fit
  if (t.mean > o.transmission_threshold) {
    if (t.peak <= o.diffuse_peak_max)
      transmission.diffuse_transmission = diffuse_transmission_factor(t);
    else
      transmission.transmission = t.share;
  }
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
  if (fit.material.diffuse_transmission > 0) fit_transmission_color(t, fit);
  fit.rms_log = best.objective;
  fit.rms_log_start = best.objective_start;
  fit.evaluations = best.evaluations;
  return fit;
}

}  // namespace weft
