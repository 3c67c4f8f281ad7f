#pragma once
// Mie scattering by homogeneous spheres (Bohren & Huffman 1983, ch. 4) with Wiscombe's term count
// (Appl. Opt. 19, 1505, 1980) and a logarithmic derivative D_n(mx) computed by downward
// recurrence from a start index far enough above |mx| that the start error has died out.
//
// Conventions (stated once, used everywhere):
// - Relative index m = n + i k, k >= 0 absorbing (Bohren-Huffman, time factor exp(-i w t)).
//   Wiscombe's MIEV0 writes m = n - i k; its S1, S2 are the complex conjugates of ours, its
//   efficiencies are the same.
// - Size parameter x = 2 pi n_host r / lambda_vacuum; m = (particle n + i k) / n_host. The host
//   is taken as non-absorbing here; a host's own absorption is added by the medium.
// - Amplitudes S1, S2 follow Bohren & Huffman eq. 4.74; efficiencies are cross sections over
//   pi r^2; Q_back = 4 pi (dC_sca/dOmega at 180 deg) / (pi r^2) (BH eq. 4.82).
// - The phase function p integrates to 1 over the sphere (1/sr):
//   p(theta) = (|S1|^2 + |S2|^2) / (2 pi x^2 Q_sca).
#include <complex>
#include <span>
#include <string>
#include <vector>

namespace weft {

struct MieResult {
  double x = 0;
  std::complex<double> m;
  double qext = 0, qsca = 0, qabs = 0, qback = 0;
  double g = 0;            // asymmetry parameter <cos theta>; 0 when nothing scatters
  int terms = 0;           // series terms summed
  std::vector<double> mu;  // cosines of the scattering angles requested
  std::vector<std::complex<double>> s1, s2;  // amplitudes at mu
};

// Size parameters accepted: below the minimum the Rayleigh limit is exact to double precision
// and the series' chi_n would approach overflow; cost and memory grow linearly with x and |m| x.
inline constexpr double kMieMinSizeParameter = 1e-12;
inline constexpr double kMieMaxSizeParameter = 1e7;
inline constexpr double kMieMaxMx = 1e8;

// Series terms: Wiscombe 1980 eq. (x + 4 x^(1/3) + 1 for x <= 8, x + 4.05 x^(1/3) + 2 up to
// 4200, x + 4 x^(1/3) + 2 beyond), never fewer than 2 so that g keeps its leading order.
int mie_term_count(double x);

// Mie efficiencies, g and (optionally) S1, S2 at the cosines mu, for relative index m and size
// parameter x. For x < 0.01 (and |m| x < 0.02) the cancelling numerators of a_1, b_1, a_2, b_2
// come from their Taylor series, as MIEV0 uses small-particle formulas there. Throws weft::Error
// (fields "m", "x", "mu") on non-finite, x <= 0, Re m <= 0, Im m < 0, or beyond the limits above.
MieResult mie_sphere(std::complex<double> m, double x, std::span<const double> mu = {});

// The physical form: particle index n + i k in a host of real index host_n, sphere radius in
// micrometres, vacuum wavelength in nanometres.
double mie_size_parameter(double host_n, double radius_um, double wavelength_nm);
MieResult mie_sphere_physical(double particle_n, double particle_k, double host_n, double radius_um,
                              double wavelength_nm, std::span<const double> mu = {});

// Normalized phase function p (1/sr) at r.mu from r's amplitudes. Isotropic (1 / 4 pi) when
// nothing scatters (m = 1).
std::vector<double> mie_phase_function(const MieResult& r);

// D_n(z) = psi_n'(z) / psi_n(z) for n = 0 .. n_max (index n), by the downward recurrence this
// solver uses. Exposed for tests.
std::vector<std::complex<double>> mie_log_derivatives(std::complex<double> z, int n_max);

// Leading-order small-particle (Rayleigh) limit, K = (m^2 - 1) / (m^2 + 2):
// Q_sca = 8/3 x^4 |K|^2, Q_abs = 4 x Im K, Q_back = 4 x^4 |K|^2, g = 0 (BH eqs. 5.7-5.8).
MieResult rayleigh_limit(std::complex<double> m, double x);

// Scattering angles (radians, 0 .. pi, strictly increasing) that resolve the forward peak of
// spheres up to size parameter x_max: spacing 0.05 / x_max near 0, growing geometrically
// (5 % per node) with the angle, capped at min(0.5 deg, 0.5 / x_max) so the interference
// ripples of the largest sphere are sampled too. At most max_nodes nodes (the cap is relaxed
// to stay under it).
std::vector<double> mie_angle_grid_rad(double x_max, int max_nodes = 20000);

// Particle size distributions. Lognormal: number density in ln r is normal with mean
// ln(median_radius) and standard deviation sigma (dimensionless).
struct SizeDistribution {
  enum class Kind { kMonodisperse, kLognormal };
  Kind kind = Kind::kMonodisperse;
  double radius_um = 0;  // monodisperse radius, or lognormal median radius
  double sigma = 0;      // lognormal only

  static SizeDistribution monodisperse(double radius_um) {
    return {Kind::kMonodisperse, radius_um, 0.0};
  }
  static SizeDistribution lognormal(double median_radius_um, double sigma) {
    return {Kind::kLognormal, median_radius_um, sigma};
  }
};
inline constexpr double kMaxLognormalSigma = 1.0;

// Radii and number weights (summing to 1) of the quadrature over a distribution: one node for
// monodisperse; for lognormal, composite 8-point Gauss-Legendre in ln r over
// [ln r_med - 5 sigma, ln r_med + 3 sigma^2 + 5 sigma] (covering the number, area and volume
// weightings). 'nodes' is rounded up to a multiple of 8.
struct SizeQuadrature {
  std::vector<double> radius_um, weight;
};
SizeQuadrature size_quadrature(const SizeDistribution& d, int nodes = 96);

// Mie averaged over a size distribution: cross sections per particle averaged over the number
// distribution, effective efficiencies <C> / <pi r^2>, g and phase function weighted by C_sca.
struct MieEnsemble {
  double mean_cext_um2 = 0, mean_csca_um2 = 0, mean_cabs_um2 = 0, mean_cback_um2 = 0;
  double mean_area_um2 = 0;                        // <pi r^2>
  double mean_volume_um3 = 0;                      // <4/3 pi r^3>
  double qext = 0, qsca = 0, qabs = 0, qback = 0;  // effective: <C> / <pi r^2>
  double g = 0;
  double x_max = 0;           // largest size parameter in the quadrature
  std::vector<double> mu;     // cosines, as passed
  std::vector<double> phase;  // normalized phase function (1/sr) at mu
};
struct MieEnsembleOptions {
  int lognormal_nodes = 96;
};
MieEnsemble mie_ensemble(double particle_n, double particle_k, double host_n,
                         const SizeDistribution& d, double wavelength_nm,
                         std::span<const double> mu, const MieEnsembleOptions& options = {});

// Throws weft::Error naming 'field' unless d is valid (radius > 0 finite, 0 < sigma <= 1).
void validate_size_distribution(const SizeDistribution& d, const std::string& file,
                                const std::string& field);

}  // namespace weft
