#include "weft/fabric/fabric_summation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {
namespace {

// A fiber orientation prepared for the layer model: its axis t, the layer's "up" n0 (the cloth's
// normal made perpendicular to t) and c0 = n0 x t across the layer, so that the point B at angle
// phi around the fiber has the normal n(phi) = cos phi n0 + sin phi c0.
struct LayerFiber {
  Vec3 t, n0, c0;
  double weight = 0;
  // The frames of the circumference's midpoints phi_k = (k + 1/2) 2 pi / samples: normal n(phi_k)
  // and n(phi_k) x t, computed once per orientation (the sines and cosines were most of the time).
  std::vector<Vec3> n, b;
  std::vector<double> sin_phi, cos_phi;
};

std::vector<LayerFiber> prepare(const std::vector<FiberOrientation>& given, int samples) {
  std::vector<FiberOrientation> list = given;
  if (list.empty()) list = {{{1, 0, 0}, 1}, {{0, 1, 0}, 1}};
  // t and -t are one fiber: cluster on the upper hemisphere of a coarse grid, so that a sample's
  // thousands of surface tangents become a few weighted orientations.
  const DirectionGrid clusters{8};
  std::map<int, std::pair<Vec3, double>> sums;
  for (const auto& o : list) {
    Vec3 t = normalize(o.tangent);
    if (t.z < 0 || (t.z == 0 && t.x < 0)) t = -t;
    auto& [sum, w] = sums[clusters.bin_of(t)];
    sum += o.weight * t;
    w += o.weight;
  }
  std::vector<LayerFiber> out;
  double total = 0;
  for (const auto& [bin, sw] : sums) {
    const auto& [sum, w] = sw;
    if (!(w > 0) || !(length(sum) > 0)) continue;
    LayerFiber f;
    f.t = normalize(sum);
    const Vec3 up = Vec3{0, 0, 1} - f.t.z * f.t;
    if (!(length(up) > 1e-6)) continue;  // a fiber standing along the normal shows no layer
    f.n0 = normalize(up);
    f.c0 = cross(f.n0, f.t);
    f.weight = w;
    total += w;
    out.push_back(f);
  }
  const double dphi = 2 * kPi / samples;
  for (auto& f : out) {
    f.weight /= total;
    for (int k = 0; k < samples; ++k) {
      const double phi = (k + 0.5) * dphi;
      const Vec3 n = std::cos(phi) * f.n0 + std::sin(phi) * f.c0;
      f.n.push_back(n);
      f.b.push_back(cross(n, f.t));
      f.sin_phi.push_back(std::sin(phi));
      f.cos_phi.push_back(std::cos(phi));
    }
  }
  return out;
}

// Direction w in the frame of circumference point k of fiber f (x = t, y = n x t, z = n).
Vec3 to_fiber_point(const LayerFiber& f, int k, const Vec3& w) {
  return {dot(w, f.t), dot(w, f.b[k]), dot(w, f.n[k])};
}

// In the cross-section of a closed layer of fibers of radius 1 at pitch 2 (centres at (2k, 0),
// coordinates (across, up)), whether the ray from the point (px, py) = (sin phi, cos phi) of the
// fiber at the origin along (dx, dy) = (sin alpha, cos alpha) misses every neighbour.
bool clear_of_neighbours(double px, double py, double dx, double dy) {
  for (int k = -4; k <= 4; ++k) {
    if (k == 0) continue;
    const double ox = px - 2 * k, oy = py;  // from the neighbour's centre to the point
    const double b = dx * ox + dy * oy;
    const double c = ox * ox + oy * oy - 1;
    if (b < 0 && b * b - c > 0) return false;
  }
  return true;
}

// One orientation's layer: s_i / (2 |cos_i| |cos_o|) * int_{seen} f |cos_i(B)| |cos_o(B)| d phi,
// by the midpoint rule on the circumference points prepared in f.
void layer_sum(const TabulatedBsdfTable& fiber, const LayerFiber& f, const Vec3& wo, const Vec3& wi,
               std::span<double> acc, std::span<double> tmp) {
  const int samples = static_cast<int>(f.n.size());
  const double cos_o = std::abs(wo.z), cos_i = std::abs(wi.z);
  if (!(cos_o > 0) || !(cos_i > 0)) return;
  // The two directions across the layer: their angles from n0 and their lengths there.
  const double on = dot(wo, f.n0), oc = dot(wo, f.c0), in = dot(wi, f.n0), ic = dot(wi, f.c0);
  const double alpha_o = std::atan2(oc, on);
  const double sin_alpha_o = std::sin(alpha_o), cos_alpha_o = std::cos(alpha_o);
  const double rho_i = std::hypot(in, ic);
  // Shadowing by the neighbours: the layer's beam width per fiber over an isolated fiber's.
  const double lit = rho_i > 1e-12 ? std::abs(in) / rho_i : 1.0;
  const double dphi = 2 * kPi / samples;
  const double scale = lit * dphi / (2 * cos_i * cos_o) * f.weight;
  for (int k = 0; k < samples; ++k) {
    const Vec3 o = to_fiber_point(f, k, wo);
    if (!(o.z > 0) || !clear_of_neighbours(f.sin_phi[k], f.cos_phi[k], sin_alpha_o, cos_alpha_o))
      continue;  // not seen from w_o
    const Vec3 i = to_fiber_point(f, k, wi);
    fiber.interpolate(o, i, tmp);
    const double w = scale * std::abs(i.z) * o.z;
    for (size_t c = 0; c < acc.size(); ++c) acc[c] += w * tmp[c];
  }
}

}  // namespace

void FabricSummationOptions::validate() const {
  if (resolution < 1 || resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (samples_per_cell < 1 || samples_per_cell > 4096)
    throw Error("", "samples", "must lie in [1, 4096]");
  if (circumference_samples < 4 || circumference_samples > 4096)
    throw Error("", "circumference_samples", "must lie in [4, 4096]");
  for (const auto* list : {&top, &bottom})
    for (const auto& o : *list)
      if (!is_finite(o.tangent) || !(length(o.tangent) > 0) || !std::isfinite(o.weight) ||
          o.weight < 0)
        throw Error("", "orientations", "tangents must be finite non-zero vectors, weights >= 0");
}

void fabric_sum(const TabulatedBsdfTable& fiber, const FabricSummationOptions& o, const Vec3& wo,
                const Vec3& wi, std::span<double> out) {
  std::fill(out.begin(), out.end(), 0.0);
  std::vector<double> tmp(fiber.channels);
  if (o.method == FabricSummation::kPaper) {
    // Warp: the fiber frame is the cloth frame; weft: t = y, n = z, b = n x t = -x.
    const Vec3 frames[2][2] = {{wo, wi}, {{wo.y, -wo.x, wo.z}, {wi.y, -wi.x, wi.z}}};
    for (const auto& fr : frames) {
      fiber.interpolate(fr[0], fr[1], tmp);
      for (int c = 0; c < fiber.channels; ++c) out[c] += 0.5 * tmp[c];
    }
    return;
  }
  const auto fibers = prepare(wo.z >= 0 ? o.top : o.bottom, o.circumference_samples);
  for (const auto& f : fibers) layer_sum(fiber, f, wo, wi, out, tmp);
}

TabulatedBsdfTable sum_fabric_table(const TabulatedBsdfTable& fiber,
                                    const FabricSummationOptions& o,
                                    const ProgressCallback& progress) {
  o.validate();
  fiber.validate("");
  if (fiber.kind != "fiber") throw Error("", "fiber", "expected a fiber table, got " + fiber.kind);
  TabulatedBsdfTable t;
  if (o.method == FabricSummation::kPaper) {
    t = TabulatedBsdfTable::from_function(
        o.resolution, fiber.channels,
        [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          fabric_sum(fiber, o, wo, wi, v);
        },
        o.samples_per_cell, o.seed, o.threads, progress);
  } else {
    // Prepared once: the clustered orientations of either side.
    const auto top = prepare(o.top, o.circumference_samples),
               bottom = prepare(o.bottom, o.circumference_samples);
    t = TabulatedBsdfTable::from_function(
        o.resolution, fiber.channels,
        [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          std::fill(v.begin(), v.end(), 0.0);
          std::vector<double> tmp(fiber.channels);
          for (const auto& f : wo.z >= 0 ? top : bottom) layer_sum(fiber, f, wo, wi, v, tmp);
        },
        o.samples_per_cell, o.seed, o.threads, progress);
  }
  t.kind = "fabric";
  t.metadata = {{"method", o.method == FabricSummation::kPaper ? "summation" : "summation-visible"},
                {"fiber_checksum", fiber.checksum()},
                {"samples_per_cell", std::to_string(o.samples_per_cell)},
                {"seed", std::to_string(o.seed)}};
  for (const char* key : {"spec_hash", "spec_name"})
    if (const auto it = fiber.metadata.find(key); it != fiber.metadata.end())
      t.metadata[std::string("fiber_") + key] = it->second;
  return t;
}

}  // namespace weft
