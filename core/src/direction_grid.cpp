#include "weft/core/direction_grid.h"

#include <algorithm>
#include <cmath>

#include "weft/core/math.h"
#include "weft/core/quadrature.h"
#include "weft/core/sphere_mapping.h"

namespace weft {
namespace {

// Integral of f(rho) = 1 - rho^2 over [a,b] x [c,d] (0 <= a < b <= 1, 0 <= c < d <= 1) with
// rho = max(s, t): |cos theta| in a hemisphere square's coordinates. Split along s = t; each part
// is a polynomial of degree <= 3 between the breakpoints, so 3-point Gauss-Legendre is exact.
double cos_integral_rect(double a, double b, double c, double d) {
  std::vector<double> x, w;
  gauss_legendre(3, x, w);
  // int_lo^hi (1 - r^2) * clamp(min(top, r) - bottom, 0) dr, with a breakpoint where r = bottom
  // and r = top.
  auto part = [&](double lo, double hi, double bottom, double top) {
    double breaks[] = {lo, std::clamp(bottom, lo, hi), std::clamp(top, lo, hi), hi};
    std::sort(std::begin(breaks), std::end(breaks));
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      const double p0 = breaks[k], p1 = breaks[k + 1];
      if (!(p1 > p0)) continue;
      const double mid = 0.5 * (p0 + p1), half = 0.5 * (p1 - p0);
      for (int q = 0; q < 3; ++q) {
        const double r = mid + half * x[q];
        sum += w[q] * half * (1 - r * r) * std::max(0.0, std::min(top, r) - bottom);
      }
    }
    return sum;
  };
  // s >= t: rho = s, t in [c, min(d, s)]; t > s: rho = t, s in [a, min(b, t)].
  return part(a, b, c, d) + part(c, d, a, b);
}

}  // namespace

double DirectionGrid::bin_solid_angle() const {
  return 2 * kPi / (static_cast<double>(resolution) * resolution);
}

Vec2 DirectionGrid::to_chart(const Vec3& d) {
  // Upper-hemisphere point of the octahedral map, in [-1, 1]^2 inside the diamond |u|+|v| <= 1.
  const Vec2 p = equal_area_sphere_to_square({d.x, d.y, std::abs(d.z)});
  const double u = 2 * p.x - 1, v = 2 * p.y - 1;
  // Turned by 45 degrees: the diamond fills the square (s, t) in [-1, 1]^2.
  const double s = std::clamp(u + v, -1.0, 1.0), t = std::clamp(v - u, -1.0, 1.0);
  const double x = 0.5 * (s + 1), yh = 0.5 * (t + 1);
  return {x, d.z >= 0 ? 0.5 * yh : 0.5 + 0.5 * yh};
}

Vec3 DirectionGrid::to_direction(Vec2 chart) {
  const bool lower = chart.y >= 0.5;
  const double yh = std::clamp(lower ? 2 * chart.y - 1 : 2 * chart.y, 0.0, 1.0);
  const double s = 2 * std::clamp(chart.x, 0.0, 1.0) - 1, t = 2 * yh - 1;
  const double u = 0.5 * (s - t), v = 0.5 * (s + t);
  Vec3 d = equal_area_square_to_sphere({0.5 * (u + 1), 0.5 * (v + 1)});
  d.z = std::abs(d.z);  // on the diamond's edge the map may return -0
  if (lower) d.z = -d.z;
  return d;
}

int DirectionGrid::bin_of_chart(Vec2 chart) const {
  const int r = resolution;
  const int x = std::clamp(static_cast<int>(std::floor(chart.x * r)), 0, r - 1);
  const int row = std::clamp(static_cast<int>(std::floor(chart.y * 2 * r)), 0, 2 * r - 1);
  return row * r + x;
}

Vec2 DirectionGrid::chart_point(int bin, double fx, double fy) const {
  const int r = resolution, x = bin % r, row = bin / r;
  return {(x + fx) / r, (row + fy) / (2.0 * r)};
}

int DirectionGrid::mirrored_bin(int bin, int axis) const {
  const int r = resolution, x = bin % r, y = (bin / r) % r, hemi = bin / (r * r);
  // In a hemisphere square (s, t) = (u + v, v - u) of the octahedral (u, v): x -> -x swaps s and
  // t, y -> -y maps (s, t) to (-t, -s), z -> -z changes the hemisphere only.
  if (axis == 0) return (hemi * r + x) * r + y;
  if (axis == 1) return (hemi * r + (r - 1 - x)) * r + (r - 1 - y);
  return ((1 - hemi) * r + y) * r + x;
}

Vec3 DirectionGrid::bin_center(int bin) const {
  return to_direction(chart_point(bin, 0.5, 0.5));
}

DirectionGrid::Footprint DirectionGrid::bilinear(Vec2 chart) const {
  const int r = resolution;
  const int hemi = chart.y >= 0.5 ? 1 : 0;
  const double yh = std::clamp(2 * chart.y - hemi, 0.0, 1.0);
  const double px = std::clamp(chart.x, 0.0, 1.0) * r - 0.5, py = yh * r - 0.5;
  const double fx0 = std::floor(px), fy0 = std::floor(py);
  const double tx = px - fx0, ty = py - fy0;
  auto cell = [&](double fx, double fy) {
    const int x = std::clamp(static_cast<int>(fx), 0, r - 1);
    const int y = std::clamp(static_cast<int>(fy), 0, r - 1);
    return (hemi * r + y) * r + x;
  };
  Footprint fp;
  fp.bin[0] = cell(fx0, fy0);
  fp.bin[1] = cell(fx0 + 1, fy0);
  fp.bin[2] = cell(fx0, fy0 + 1);
  fp.bin[3] = cell(fx0 + 1, fy0 + 1);
  fp.weight[0] = (1 - tx) * (1 - ty);
  fp.weight[1] = tx * (1 - ty);
  fp.weight[2] = (1 - tx) * ty;
  fp.weight[3] = tx * ty;
  return fp;
}

std::vector<double> DirectionGrid::cosine_weighted_areas() const {
  const int r = resolution;
  std::vector<double> square(static_cast<size_t>(r) * r, 0.0);
  for (int iy = 0; iy < r; ++iy)
    for (int ix = 0; ix < r; ++ix) {
      // The bin in (s, t) in [-1, 1]^2, split at the axes so that each piece lies in one quadrant.
      const double s0 = 2.0 * ix / r - 1, s1 = 2.0 * (ix + 1) / r - 1;
      const double t0 = 2.0 * iy / r - 1, t1 = 2.0 * (iy + 1) / r - 1;
      double total = 0;
      for (auto [sa, sb] : {std::pair{s0, std::min(s1, 0.0)}, std::pair{std::max(s0, 0.0), s1}})
        for (auto [ta, tb] : {std::pair{t0, std::min(t1, 0.0)}, std::pair{std::max(t0, 0.0), t1}}) {
          if (!(sb > sa) || !(tb > ta)) continue;
          // Reflect into the first quadrant.
          total += cos_integral_rect(
              std::min(std::abs(sa), std::abs(sb)), std::max(std::abs(sa), std::abs(sb)),
              std::min(std::abs(ta), std::abs(tb)), std::max(std::abs(ta), std::abs(tb)));
        }
      square[static_cast<size_t>(iy) * r + ix] = 0.5 * kPi * total;  // d omega = pi/2 ds dt
    }
  // Both hemispheres alike.
  std::vector<double> out(square);
  out.insert(out.end(), square.begin(), square.end());
  return out;
}

}  // namespace weft
