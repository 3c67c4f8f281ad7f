#include "weft/fiber/mie.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <string>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/quadrature.h"

namespace weft {
namespace {

using cd = std::complex<double>;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Complex division by Smith's method (Comm. ACM 5, 435, 1962): as robust against overflow as the
// library's, without its out-of-line call, which dominated the cost per term.
inline cd cdiv(cd a, cd b) {
  const double br = b.real(), bi = b.imag();
  if (std::abs(br) >= std::abs(bi)) {
    const double r = bi / br, den = br + bi * r;
    return {(a.real() + a.imag() * r) / den, (a.imag() - a.real() * r) / den};
  }
  const double r = br / bi, den = bi + br * r;
  return {(a.real() * r + a.imag()) / den, (a.imag() * r - a.real()) / den};
}

// Small-sphere numerators. With da = D_n(mx)/m + n/x (a_n) or m D_n(mx) + n/x (b_n), the series
// terms are a_n = P / (P - i Q), P = da psi_n(x) - psi_{n-1}(x), Q = da chi_n(x) - chi_{n-1}(x).
// For small x, P is a difference of terms larger by 1/x^2, so it loses digits as eps / x^2
// (b_1 and a_2, and hence g, first); Q does not cancel. MIEV0 switches to small-particle
// formulas there; we expand P itself. Taylor series in x (derived with sympy from the series of
// psi_n and D_n), every coefficient carrying the factor u - 1 = m^2 - 1 exactly:
struct SmallNumerators {
  cd a1, b1, a2, b2;
};

// One coefficient of a series in x^2: a polynomial in u (highest power first) over an integer.
struct SeriesCoefficient {
  std::initializer_list<double> poly;
  double denominator;
};

// sum_k x2^k c_k(u), nested from the highest term (Horner in x2 and in u).
cd series_in_x2(std::initializer_list<SeriesCoefficient> terms, cd u, double x2) {
  cd sum = 0.0;
  for (auto t = std::rbegin(terms); t != std::rend(terms); ++t) {
    cd c = 0.0;
    for (const double p : t->poly) c = c * u + p;
    sum = c / t->denominator + x2 * sum;
  }
  return sum;
}

SmallNumerators small_sphere_numerators(cd m, double x) {
  const cd u = m * m, um1 = (m - 1.0) * (m + 1.0);  // exact for m near 1
  const double x2 = x * x;
  // One series per line: a1, b1, a2, b2 (coefficients of x2^0 .. x2^4).
  // clang-format off
  const cd s_a1 = series_in_x2({{{-2}, 3}, {{1}, 15}, {{-4, -5}, 2100}, {{-48, 60, 25}, 567000}, {{-7104, 7680, -4200, -875}, 1746360000}}, u, x2);
  const cd s_b1 = series_in_x2({{{-1}, 15}, {{-2, 5}, 1050}, {{-16, 20, -25}, 189000}, {{-1776, 1920, -1050, 875}, 436590000}, {{-45312, 47040, -21600, 7000, -4375}, 227026800000}}, u, x2);
  const cd s_a2 = series_in_x2({{{-1}, 5}, {{1}, 70}, {{-8, -21}, 52920}, {{-32, 56, 49}, 8149680}, {{-6016, 8960, -7056, -3087}, 53396703360}}, u, x2);
  const cd s_b2 = series_in_x2({{{-1}, 105}, {{-2, 7}, 13230}, {{-16, 28, -49}, 4074840}, {{-752, 1120, -882, 1029}, 6674587920}, {{-18688, 26432, -17248, 8232, -7203}, 5606653852800}}, u, x2);
  // clang-format on
  return {um1 / u * x * s_a1, um1 * x * x2 * s_b1, um1 / u * x2 * s_a2, um1 * x2 * x2 * s_b2};
}

// Where the expansions are used: truncated after (m x)^8 relative terms, they are good to
// 1e-16 for |m x| < 0.02; below x = 0.01 the direct difference would lose more than 1e-12.
bool use_small_sphere_series(cd m, double x) {
  return x < 0.01 && std::abs(m) * x < 0.02;
}

void validate_index_and_size(cd m, double x) {
  if (!std::isfinite(m.real()) || !std::isfinite(m.imag()))
    throw Error("", "m", "relative refractive index is not finite");
  if (!(m.real() > 0)) throw Error("", "m", "real part of the relative index must be > 0");
  if (m.imag() < 0)
    throw Error("", "m", "imaginary part must be >= 0 (m = n + ik with k >= 0 absorbing)");
  if (!std::isfinite(x) || !(x > 0)) throw Error("", "x", "size parameter must be finite and > 0");
  if (x < kMieMinSizeParameter)
    throw Error("", "x",
                "size parameter " + num(x) + " below the limit " + num(kMieMinSizeParameter) +
                    " (use the Rayleigh limit)");
  if (x > kMieMaxSizeParameter)
    throw Error("", "x",
                "size parameter " + num(x) + " above the limit " + num(kMieMaxSizeParameter));
  if (std::abs(m) * x > kMieMaxMx)
    throw Error("", "m", "|m| x = " + num(std::abs(m) * x) + " above the limit " + num(kMieMaxMx));
}

// psi_{n-1}(z) / psi_n(z) by the continued fraction that the three-term recurrence
// psi_{n-1} + psi_{n+1} = (2n + 1) / z psi_n implies, evaluated with Lentz's method
// (Appl. Opt. 15, 668, 1976; modified form with a tiny floor for zero denominators).
cd ratio_continued_fraction(cd z, int n) {
  constexpr double kTiny = 1e-300;
  const cd inv_z = 1.0 / z;
  cd f = static_cast<double>(2 * n + 1) * inv_z;
  if (std::abs(f) < kTiny) f = kTiny;
  cd c = f, d = 0.0;
  // Called beyond the turning point only, where it converges in a few dozen steps; the cap is
  // a guard, and the downward recurrence damps whatever start error remains.
  for (int j = 1; j < 100000; ++j) {
    const cd b = static_cast<double>(2 * (n + j) + 1) * inv_z;
    d = b - d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b - 1.0 / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const cd delta = c * d;
    f *= delta;
    if (std::abs(delta - 1.0) < 4e-16) break;  // a couple of ulps: converged
  }
  return f;
}

// Where the downward recurrence for D_n(z) starts. Past the turning point n ~ |z| the regular
// solution psi_n decays like Ai(t), t = (n - |z|) / (|z| / 2)^(1/3), and an error in the start
// value is damped by about psi_N / chi_N ~ exp(-4/3 t^(3/2)) relative to the terms we keep:
// t = 10 makes that < 1e-18. BHMIE's fixed |z| + 15 has t << 1 for large |z|, which is why it
// loses digits for large weakly absorbing spheres (Du 2004); we also start from the exact
// continued-fraction value, so the margin is a second line of defence.
int log_derivative_start(cd z, int n_max) {
  const double az = std::abs(z);
  const double turning = az + 10.0 * std::cbrt(0.5 * az);
  return static_cast<int>(std::ceil(std::max(static_cast<double>(n_max), turning))) + 16;
}

void validate_mu(std::span<const double> mu) {
  for (size_t i = 0; i < mu.size(); ++i)
    if (!std::isfinite(mu[i]) || mu[i] < -1 || mu[i] > 1)
      throw Error("", "mu", "cosine " + std::to_string(i) + " is not finite or outside [-1, 1]");
}

}  // namespace

int mie_term_count(double x) {
  const double c = std::cbrt(x);
  double n;
  if (x <= 8)
    n = x + 4 * c + 1;
  else if (x < 4200)
    n = x + 4.05 * c + 2;
  else
    n = x + 4 * c + 2;
  return std::max(2, static_cast<int>(n));
}

std::vector<cd> mie_log_derivatives(cd z, int n_max) {
  if (!std::isfinite(z.real()) || !std::isfinite(z.imag()) || std::abs(z) == 0)
    throw Error("", "z", "argument must be finite and non-zero");
  if (n_max < 0) throw Error("", "n_max", "must be >= 0");
  std::vector<cd> out(n_max + 1);
  const cd inv_z = 1.0 / z;
  const int start = log_derivative_start(z, n_max);
  cd d = ratio_continued_fraction(z, start) - static_cast<double>(start) * inv_z;
  if (start <= n_max) out[start] = d;
  for (int n = start; n >= 1; --n) {
    const cd n_z = static_cast<double>(n) * inv_z;
    cd denom = d + n_z;  // psi_{n-1} / psi_n; zero only where psi_{n-1}(z) = 0 exactly
    if (std::abs(denom) < 1e-300) denom = 1e-300;
    d = n_z - cdiv(1.0, denom);
    if (n - 1 <= n_max) out[n - 1] = d;
  }
  return out;
}

namespace {

// psi_n(x) for n = 0..nstop (x < 1) from the downward ratio recurrence, normalized by
// psi_0 = sin x: the upward one cancels there.
std::vector<double> psi_downward(double x, int nstop) {
  std::vector<double> psi(nstop + 1, 0.0);
  const int top = nstop + 20;
  double ratio = (2.0 * top + 3) / x;  // psi_top / psi_{top+1}, leading order
  std::vector<double> ratios(nstop + 1, 0.0);
  for (int n = top; n >= 1; --n) {
    ratio = (2.0 * n + 1) / x - 1.0 / ratio;  // psi_{n-1} / psi_n
    if (n <= nstop) ratios[n] = ratio;
  }
  psi[0] = std::sin(x);
  for (int n = 1; n <= nstop; ++n) psi[n] = psi[n - 1] / ratios[n];
  return psi;
}

// Adds term n (coefficients a_n, b_n) to the amplitudes r.s1, r.s2 at every mu. Angular
// functions (BH eq. 4.47): pi_n = (2n-1)/(n-1) mu pi_{n-1} - n/(n-1) pi_{n-2},
// tau_n = n mu pi_n - (n+1) pi_{n-1}. On entry pi_n[] holds pi_{n-1}, pi_nm1[] pi_{n-2}; on
// return pi_n and pi_{n-1}.
void add_amplitude_terms(int n, cd a, cd b, std::span<const double> mu, std::vector<double>& pi_nm1,
                         std::vector<double>& pi_n, MieResult& r) {
  const double dn_d = static_cast<double>(n);
  const double w = 2 * dn_d + 1;
  const double fn = w / (dn_d * (dn_d + 1));
  const double c1 = n > 1 ? (2 * dn_d - 1) / (dn_d - 1) : 0.0;
  const double c2 = n > 1 ? dn_d / (dn_d - 1) : 0.0;
  for (size_t i = 0; i < mu.size(); ++i) {
    const double p_nm1 = n > 1 ? pi_n[i] : 0.0;
    const double p_n = n > 1 ? c1 * mu[i] * p_nm1 - c2 * pi_nm1[i] : 1.0;
    const double tau = dn_d * mu[i] * p_n - (dn_d + 1) * p_nm1;
    r.s1[i] += fn * (a * p_n + b * tau);
    r.s2[i] += fn * (a * tau + b * p_n);
    pi_nm1[i] = p_nm1;
    pi_n[i] = p_n;
  }
}

}  // namespace

MieResult mie_sphere(cd m, double x, std::span<const double> mu) {
  validate_index_and_size(m, x);
  validate_mu(mu);
  MieResult r;
  r.x = x;
  r.m = m;
  r.mu.assign(mu.begin(), mu.end());
  const size_t na = mu.size();
  r.s1.assign(na, 0.0);
  r.s2.assign(na, 0.0);
  if (m == cd(1.0, 0.0)) return r;  // no contrast: nothing scatters or absorbs

  const int nstop = mie_term_count(x);
  r.terms = nstop;
  const std::vector<cd> dn = mie_log_derivatives(m * x, nstop);

  // Riccati-Bessel psi_n(x) = x j_n(x) and chi_n(x) = -x y_n(x). chi grows with n, so its upward
  // recurrence is stable. psi's upward recurrence is fine for n up to ~x (MIEV0 and BHMIE use
  // it), but for x < 1 its first step sin x / x - cos x cancels (relative error eps / x^2), so
  // there psi comes from the downward ratio recurrence normalized by psi_0 = sin x. Below
  // x = 0.01 the numerators P themselves come from their series (small_sphere_numerators).
  const bool series = use_small_sphere_series(m, x);  // then nstop == 2
  const SmallNumerators small = series ? small_sphere_numerators(m, x) : SmallNumerators{};
  const bool small_x = x < 1;
  const std::vector<double> psi_small = small_x ? psi_downward(x, nstop) : std::vector<double>{};

  double psi_nm2 = std::cos(x), psi_nm1 = std::sin(x);
  double chi_nm2 = -std::sin(x), chi_nm1 = std::cos(x);
  const double inv_x = 1.0 / x;
  const cd inv_m = 1.0 / m;

  double sum_ext = 0, sum_sca = 0, sum_g = 0;
  cd sum_back = 0, a_prev = 0, b_prev = 0;
  std::vector<double> pi_nm1(na, 0.0), pi_n(na, 1.0);  // pi_0 = 0, pi_1 = 1

  for (int n = 1; n <= nstop; ++n) {
    const double dn_d = static_cast<double>(n);
    const double f = (2 * dn_d - 1) * inv_x;
    const double chi_n = f * chi_nm1 - chi_nm2;
    const double psi_n = small_x ? psi_small[n] : f * psi_nm1 - psi_nm2;
    const double n_x = dn_d * inv_x;
    const cd da = dn[n] * inv_m + n_x, db = m * dn[n] + n_x;
    cd pa = da * psi_n - psi_nm1, pb = db * psi_n - psi_nm1;
    if (series && n <= 2) {
      pa = n == 1 ? small.a1 : small.a2;
      pb = n == 1 ? small.b1 : small.b2;
    }
    const cd qa = da * chi_n - chi_nm1, qb = db * chi_n - chi_nm1;
    const cd a = cdiv(pa, pa - cd(0, 1) * qa);
    const cd b = cdiv(pb, pb - cd(0, 1) * qb);

    const double w = 2 * dn_d + 1;
    sum_ext += w * (a.real() + b.real());
    sum_sca += w * (std::norm(a) + std::norm(b));
    sum_back += (n % 2 == 0 ? w : -w) * (a - b);
    if (n > 1)  // the (n-1) cross term of g Q_sca (BH p. 120) needs a_n and b_n
      sum_g +=
          (dn_d - 1) * (dn_d + 1) / dn_d * (a_prev * std::conj(a) + b_prev * std::conj(b)).real();
    sum_g += w / (dn_d * (dn_d + 1)) * (a * std::conj(b)).real();

    if (na > 0) add_amplitude_terms(n, a, b, mu, pi_nm1, pi_n, r);

    a_prev = a;
    b_prev = b;
    psi_nm2 = psi_nm1;
    psi_nm1 = psi_n;
    chi_nm2 = chi_nm1;
    chi_nm1 = chi_n;
  }

  const double inv_x2 = inv_x * inv_x;
  r.qext = 2 * inv_x2 * sum_ext;
  r.qsca = 2 * inv_x2 * sum_sca;
  r.qabs = r.qext - r.qsca;
  r.qback = inv_x2 * std::norm(sum_back);
  r.g = r.qsca > 0 ? 4 * inv_x2 * sum_g / r.qsca : 0.0;
  return r;
}

double mie_size_parameter(double host_n, double radius_um, double wavelength_nm) {
  if (!std::isfinite(host_n) || !(host_n > 0)) throw Error("", "host_n", "must be finite and > 0");
  if (!std::isfinite(radius_um) || !(radius_um > 0))
    throw Error("", "radius_um", "must be finite and > 0");
  if (!std::isfinite(wavelength_nm) || !(wavelength_nm > 0))
    throw Error("", "wavelength_nm", "must be finite and > 0");
  return 2 * kPi * host_n * radius_um / (wavelength_nm * 1e-3);
}

MieResult mie_sphere_physical(double particle_n, double particle_k, double host_n, double radius_um,
                              double wavelength_nm, std::span<const double> mu) {
  if (!std::isfinite(particle_n) || !(particle_n > 0))
    throw Error("", "particle_n", "must be finite and > 0");
  if (!std::isfinite(particle_k) || particle_k < 0)
    throw Error("", "particle_k", "must be finite and >= 0");
  const double x = mie_size_parameter(host_n, radius_um, wavelength_nm);
  return mie_sphere(cd(particle_n, particle_k) / host_n, x, mu);
}

std::vector<double> mie_phase_function(const MieResult& r) {
  std::vector<double> p(r.mu.size(), kInv4Pi);
  if (!(r.qsca > 0)) return p;
  const double scale = 1.0 / (2 * kPi * r.x * r.x * r.qsca);
  for (size_t i = 0; i < p.size(); ++i) p[i] = (std::norm(r.s1[i]) + std::norm(r.s2[i])) * scale;
  return p;
}

MieResult rayleigh_limit(cd m, double x) {
  validate_index_and_size(m, x);
  const cd m2 = m * m;
  const cd k = (m2 - 1.0) / (m2 + 2.0);
  MieResult r;
  r.x = x;
  r.m = m;
  const double x4 = x * x * x * x;
  r.qsca = 8.0 / 3.0 * x4 * std::norm(k);
  r.qabs = 4 * x * k.imag();
  r.qext = r.qsca + r.qabs;
  r.qback = 4 * x4 * std::norm(k);
  r.g = 0;
  return r;
}

std::vector<double> mie_angle_grid_rad(double x_max, int max_nodes) {
  if (!std::isfinite(x_max) || !(x_max > 0)) throw Error("", "x_max", "must be finite and > 0");
  if (max_nodes < 64) throw Error("", "max_nodes", "must be >= 64");
  const double h0 = 0.05 / x_max;
  auto build = [&](double cap) {
    std::vector<double> t{0.0};
    double theta = 0;
    while (true) {
      const double h = std::min(cap, std::max(h0, 0.05 * theta));
      theta += h;
      if (theta > kPi - 0.5 * h) break;
      t.push_back(theta);
      if (t.size() > static_cast<size_t>(max_nodes)) break;
    }
    t.push_back(kPi);
    return t;
  };
  double cap = std::min(deg_to_rad(0.5), 0.5 / x_max);
  std::vector<double> grid = build(cap);
  while (grid.size() > static_cast<size_t>(max_nodes)) {
    cap *= 1.25 * static_cast<double>(grid.size()) / max_nodes;
    grid = build(cap);
  }
  return grid;
}

void validate_size_distribution(const SizeDistribution& d, const std::string& file,
                                const std::string& field) {
  if (!std::isfinite(d.radius_um) || !(d.radius_um > 0))
    throw Error(file, field + ".radius_um", "radius must be finite and > 0");
  if (d.kind == SizeDistribution::Kind::kLognormal) {
    if (!std::isfinite(d.sigma) || !(d.sigma > 0) || d.sigma > kMaxLognormalSigma)
      throw Error(file, field + ".sigma",
                  "lognormal sigma must lie in (0, " + num(kMaxLognormalSigma) + "]");
  }
}

SizeQuadrature size_quadrature(const SizeDistribution& d, int nodes) {
  validate_size_distribution(d, "", "size");
  SizeQuadrature q;
  if (d.kind == SizeDistribution::Kind::kMonodisperse) {
    q.radius_um = {d.radius_um};
    q.weight = {1.0};
    return q;
  }
  if (nodes < 8) throw Error("", "lognormal_nodes", "must be >= 8");
  constexpr int kPerPanel = 8;
  const int panels = (nodes + kPerPanel - 1) / kPerPanel;
  std::vector<double> gx, gw;
  gauss_legendre(kPerPanel, gx, gw);
  const double mean = std::log(d.radius_um), s = d.sigma;
  const double lo = mean - 5 * s, hi = mean + 3 * s * s + 5 * s;
  const double h = (hi - lo) / panels;
  double total = 0;
  for (int p = 0; p < panels; ++p) {
    const double mid = lo + (p + 0.5) * h;
    for (int i = 0; i < kPerPanel; ++i) {
      const double t = mid + 0.5 * h * gx[i];
      const double z = (t - mean) / s;
      const double w = 0.5 * h * gw[i] * std::exp(-0.5 * z * z);
      q.radius_um.push_back(std::exp(t));
      q.weight.push_back(w);
      total += w;
    }
  }
  for (auto& w : q.weight) w /= total;
  return q;
}

MieEnsemble mie_ensemble(double particle_n, double particle_k, double host_n,
                         const SizeDistribution& d, double wavelength_nm,
                         std::span<const double> mu, const MieEnsembleOptions& options) {
  if (!std::isfinite(particle_n) || !(particle_n > 0))
    throw Error("", "particle_n", "must be finite and > 0");
  if (!std::isfinite(particle_k) || particle_k < 0)
    throw Error("", "particle_k", "must be finite and >= 0");
  if (!std::isfinite(host_n) || !(host_n > 0)) throw Error("", "host_n", "must be finite and > 0");
  if (!std::isfinite(wavelength_nm) || !(wavelength_nm > 0))
    throw Error("", "wavelength_nm", "must be finite and > 0");
  const SizeQuadrature q = size_quadrature(d, options.lognormal_nodes);
  const double wavenumber = 2 * kPi * host_n / (wavelength_nm * 1e-3);  // in the host, 1/um
  const cd m = cd(particle_n, particle_k) / host_n;

  MieEnsemble e;
  e.mu.assign(mu.begin(), mu.end());
  std::vector<double> dcsca(mu.size(), 0.0);  // <dC_sca / dOmega>, um^2 / sr
  double g_csca = 0;
  for (size_t i = 0; i < q.radius_um.size(); ++i) {
    const double r = q.radius_um[i], w = q.weight[i];
    const double x = wavenumber * r;
    e.x_max = std::max(e.x_max, x);
    const MieResult res = mie_sphere(m, x, mu);
    const double area = kPi * r * r;
    e.mean_area_um2 += w * area;
    e.mean_volume_um3 += w * (4.0 / 3.0) * kPi * r * r * r;
    e.mean_cext_um2 += w * area * res.qext;
    e.mean_csca_um2 += w * area * res.qsca;
    e.mean_cabs_um2 += w * area * res.qabs;
    e.mean_cback_um2 += w * area * res.qback;
    g_csca += w * area * res.qsca * res.g;
    const double scale = w / (2 * wavenumber * wavenumber);
    for (size_t j = 0; j < mu.size(); ++j)
      dcsca[j] += scale * (std::norm(res.s1[j]) + std::norm(res.s2[j]));
  }
  if (particle_k == 0) {
    // A real index absorbs nothing; the series' Q_ext - Q_sca is only rounding.
    e.mean_cabs_um2 = 0;
    e.mean_cext_um2 = e.mean_csca_um2;
  }
  e.qext = e.mean_cext_um2 / e.mean_area_um2;
  e.qsca = e.mean_csca_um2 / e.mean_area_um2;
  e.qabs = e.mean_cabs_um2 / e.mean_area_um2;
  e.qback = e.mean_cback_um2 / e.mean_area_um2;
  e.phase.assign(mu.size(), kInv4Pi);
  if (e.mean_csca_um2 > 0) {
    e.g = g_csca / e.mean_csca_um2;
    for (size_t j = 0; j < mu.size(); ++j) e.phase[j] = dcsca[j] / e.mean_csca_um2;
  }
  return e;
}

}  // namespace weft
