#include "weft/fiber/rough_dielectric.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/fresnel.h"

namespace weft {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kInvSqrtPi = 0.56418958354775628695;

// Heights uniform on [-1, 1] (Heitz et al. 2016 use it; a Smith walk's result does not depend on
// the height distribution, only on the masking it implies). C1 is their height CDF.
double c1(double h) {
  return std::clamp(0.5 * (h + 1), 0.0, 1.0);
}
double inv_c1(double u) {
  return 2 * u - 1;
}

// Solves cdf(x) = u for a continuous increasing cdf on [lo, hi] (cdf_pdf returns the pair):
// Newton steps kept inside a shrinking bracket (bisection when a step leaves it), to double
// precision. Deterministic: a fixed function of u.
template <class CdfPdf>
double invert_cdf(const CdfPdf& cdf_pdf, double u, double lo, double hi) {
  double x = std::clamp(0.0, lo, hi);
  for (int i = 0; i < 200; ++i) {
    const auto [c, p] = cdf_pdf(x);
    const double f = c - u;
    if (f > 0)
      hi = x;
    else
      lo = x;
    if (std::abs(f) < 1e-15 || hi - lo < 1e-13 * std::max(1.0, std::abs(x))) break;
    double next = p > 0 ? x - f / p : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    x = next;
  }
  return x;
}

// Visible slope (x along the incident direction's azimuth) for unit roughness Beckmann slopes
// exp(-x^2 - y^2) / pi seen from polar angle theta (cos_t may be negative: a photon travelling
// upwards meets facets from below). Density (cos_t - x sin_t) exp(-x^2) / sqrt(pi) for x < cot
// theta (Heitz and d'Eon 2014, sec. 4; Heitz et al. 2016's supplemental sampleP22_11).
double beckmann_visible_slope_x(double cos_t, double sin_t, double u) {
  const double a = cos_t / sin_t;
  if (a >= 0) {
    // CDF: (cos erfc(-x) / 2 + sin exp(-x^2) / (2 sqrt pi)) / norm, every term positive.
    const double norm = 0.5 * cos_t * std::erfc(-a) + 0.5 * sin_t * kInvSqrtPi * std::exp(-a * a);
    const auto cdf_pdf = [&](double x) {
      const double e = std::exp(-x * x);
      return std::pair{(0.5 * cos_t * std::erfc(-x) + 0.5 * sin_t * kInvSqrtPi * e) / norm,
                       e * (cos_t - x * sin_t) * kInvSqrtPi / norm};
    };
    return invert_cdf(cdf_pdf, u, -9.0, std::min(a, 9.0));
  }
  // Below the horizon, in t = -x >= b = -a: density (t - b) exp(-t^2) / S(b) with the tail
  // S(t) = exp(-t^2) / 2 - b sqrt(pi) erfc(t) / 2 (positive; its cancellation costs at most
  // ~2 b^2 ulps). Past b = 20 the visible facets are a sliver at t = b that a photon meets with
  // probability below 1e-170 (Lambda ~ exp(-b^2)): take it.
  const double b = -a;
  if (b > 20) return a;
  const double sqrt_pi = 1 / kInvSqrtPi;
  const auto tail = [&](double t) {
    return 0.5 * std::exp(-t * t) - 0.5 * b * sqrt_pi * std::erfc(t);
  };
  const double norm = tail(b);
  if (!(norm > 0)) return a;
  const auto cdf_pdf = [&](double t) {  // of T, increasing in t
    return std::pair{1 - tail(t) / norm, (t - b) * std::exp(-t * t) / norm};
  };
  return -invert_cdf(cdf_pdf, 1 - u, b, b + 9);
}

Vec3 beckmann_visible_normal(const Vec3& w, double alpha, Vec2 u) {
  // Stretch to unit roughness, sample the visible slopes there, rotate to w's azimuth, unstretch.
  const Vec3 ws = normalize(Vec3{alpha * w.x, alpha * w.y, w.z});
  const double sin_t = std::hypot(ws.x, ws.y), cos_t = ws.z;
  double sx = 0, sy = 0;
  if (sin_t < 1e-9 && cos_t > 0) {  // straight down onto the surface: all slopes equally visible
    const double r = std::sqrt(-std::log1p(-u.x)), phi = 2 * kPi * u.y;
    sx = r * std::cos(phi), sy = r * std::sin(phi);
  } else {
    const double x = beckmann_visible_slope_x(cos_t, std::max(sin_t, 1e-300), u.x);
    const auto cdf_pdf = [](double y) {
      const double e = std::exp(-y * y);
      return std::pair{0.5 * std::erfc(-y), kInvSqrtPi * e};
    };
    const double y = invert_cdf(cdf_pdf, u.y, -9.0, 9.0);
    const double c = sin_t > 0 ? ws.x / sin_t : 1, s = sin_t > 0 ? ws.y / sin_t : 0;
    sx = c * x - s * y, sy = s * x + c * y;
  }
  return normalize(Vec3{-alpha * sx, -alpha * sy, 1});
}

Vec3 flip_z(const Vec3& v) {
  return {v.x, v.y, -v.z};
}

double beta_function(double a, double b) {
  return std::exp(std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b));
}

}  // namespace

RoughDielectricInterface::RoughDielectricInterface(MicrofacetModel model, double alpha,
                                                   double n_outside, double n_inside)
    : dist_{model, alpha}, n_outside_(n_outside), n_inside_(n_inside) {
  if (!std::isfinite(alpha) || !(alpha > 0) || alpha > 1)
    throw Error("", "alpha", "roughness must lie in (0, 1]");
  if (!std::isfinite(n_outside) || !(n_outside >= 1e-6))
    throw Error("", "n_outside", "refractive index must be finite and >= 1e-6");
  if (!std::isfinite(n_inside) || !(n_inside >= 1e-6))
    throw Error("", "n_inside", "refractive index must be finite and >= 1e-6");
}

double RoughDielectricInterface::lambda(const Vec3& w) const {
  if (w.z > 0) return dist_.lambda(w);
  if (w.z < 0) return -1 - dist_.lambda(-w);
  return kInf;
}

Vec3 RoughDielectricInterface::sample_visible_normal(const Vec3& w, Vec2 u) const {
  if (dist_.model == MicrofacetModel::kBeckmann) return beckmann_visible_normal(w, dist_.alpha, u);
  // Heitz 2018's GGX routine; its warp of the projected disk holds for w below the horizon too
  // (the visible region's lower edge is the ellipse at -w.z, above the centre when w.z < 0).
  return dist_.sample_normal(w, u);
}

RoughDielectricScatter RoughDielectricInterface::scatter(const Vec3& d, Rng& rng) const {
  if (n_outside_ == n_inside_) return {d, d.z > 0, false, 0};
  // State in the outside frame: travelling direction, height, side. Each step works in the
  // frame of the current side (z flipped inside: the same microsurface seen from below, as the
  // uniform heights and isotropic slopes are symmetric) and maps back.
  Vec3 wr = d;
  bool outside = !(d.z > 0);
  double hr = outside ? 2.0 : -2.0;  // above (below) every microfacet: C1 = 1
  for (int order = 0;;) {
    const Vec3 ws = outside ? wr : flip_z(wr);
    const double hs = outside ? hr : -hr;
    const double u = rng.uniform();
    // Next height (Heitz et al. 2016, Alg. 2 and eq. 8): upwards the photon leaves with
    // probability G1 = C1(h)^Lambda; downwards (Lambda <= -1) it always meets the surface.
    double h_next = hs;
    if (ws.z != 0) {
      const double lam = lambda(ws);
      if (ws.z > 0) {
        if (lam == 0 || u > 1 - std::pow(c1(hs), lam))
          return {normalize(wr), outside, false, order};
        h_next = inv_c1(c1(hs) / std::pow(1 - u, 1 / lam));
      } else {
        h_next = inv_c1(c1(hs) * std::pow(1 - u, -1 / lam));
      }
    }  // horizontal: meets the surface where it is
    hr = outside ? h_next : -h_next;
    if (++order > kMaxOrder) return {normalize(wr), outside, true, order};
    // A visible microfacet for the direction the photon came from, then Fresnel on it.
    const Vec3 wi = -ws;
    const Vec2 uv{rng.uniform(), rng.uniform()};
    const Vec3 wm = sample_visible_normal(wi, uv);
    const double n_here = outside ? n_outside_ : n_inside_,
                 n_there = outside ? n_inside_ : n_outside_;
    const double cos_i = std::max(0.0, dot(wi, wm));
    double cos_t = 0;
    const double f = fresnel_dielectric(cos_i, n_here, n_there, &cos_t);
    Vec3 wo;
    bool refracted = false;
    if (rng.uniform() < f) {
      wo = -wi + 2 * cos_i * wm;
    } else {
      const double eta = n_here / n_there;
      wo = -eta * wi + (eta * cos_i - cos_t) * wm;
      refracted = true;
    }
    wo = normalize(wo);
    wr = outside ? wo : flip_z(wo);
    if (refracted) outside = !outside;
  }
}

RoughDielectricAlbedo RoughDielectricInterface::single_scatter_albedo(const Vec3& w,
                                                                      bool from_inside,
                                                                      int theta_nodes,
                                                                      int phi_nodes) const {
  RoughDielectricAlbedo a;
  if (!(w.z > 0)) return a;
  const double n_here = from_inside ? n_inside_ : n_outside_;
  const double n_there = from_inside ? n_outside_ : n_inside_;
  if (n_here == n_there) {
    a.transmitted = 1;
    return a;
  }
  const double eta = n_here / n_there;
  const double lam_i = dist_.lambda(w);
  const double alpha = dist_.alpha;
  // Normals by psi with tan theta_h = alpha tan psi (midpoint rule in psi and phi): the nodes
  // follow the slope scale at any roughness and reach the horizon (GGX's long tail).
  const double dpsi = 0.5 * kPi / theta_nodes, dphi = 2 * kPi / phi_nodes;
  for (int i = 0; i < theta_nodes; ++i) {
    const double psi = (i + 0.5) * dpsi;
    const double tp = std::tan(psi);
    const double theta = std::atan(alpha * tp);
    const double dtheta = alpha / (std::cos(psi) * std::cos(psi) * (1 + alpha * alpha * tp * tp));
    const double st = std::sin(theta), ct = std::cos(theta);
    const double dh0 = st * dtheta * dpsi * dphi;
    for (int j = 0; j < phi_nodes; ++j) {
      const double phi = (j + 0.5) * dphi;
      const Vec3 h{st * std::cos(phi), st * std::sin(phi), ct};
      const double c = dot(w, h);
      if (!(c > 0)) continue;
      // D_w(h) dh = G1(w) c D(h) / w.z dh; the first hit's height u = C1 has density
      // (1 + Lambda_i) u^Lambda_i; leaving after reflection: u^Lambda_r, after refraction
      // (from below): (1 - u)^Lambda_t. Integrated over u: G2 / G1 = (1 + Lambda_i) /
      // (1 + Lambda_i + Lambda_r) and (1 + Lambda_i) B(1 + Lambda_i, 1 + Lambda_t).
      const double weight = c * dist_.d(h) / w.z * dh0;
      double cos_t = 0;
      const double f = fresnel_dielectric(c, n_here, n_there, &cos_t);
      const Vec3 wr = -w + 2 * c * h;
      if (wr.z > 0) a.reflected += weight * f / (1 + lam_i + dist_.lambda(wr));
      if (f < 1) {
        const Vec3 wt = -eta * w + (eta * c - cos_t) * h;
        if (wt.z < 0)
          a.transmitted +=
              weight * (1 - f) * beta_function(1 + lam_i, 1 + dist_.lambda(flip_z(normalize(wt))));
      }
    }
  }
  return a;
}

}  // namespace weft
