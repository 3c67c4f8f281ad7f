// The fiber BSSRDF recorder: normalization (units), exact non-scattering cases, symmetry and
// energy bookkeeping.
#include <gtest/gtest.h>

#include <cmath>

#include "transport_test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/fabric/transport_bssrdf.h"
#include "weft/materials/fresnel.h"

using namespace weft;

namespace {

BssrdfSetup setup(double mua, double mus, double g, double n, const Vec3& incident) {
  BssrdfSetup s;
  s.medium.mu_a = mua;
  s.medium.mu_s = mus;
  s.medium.n = n;
  s.medium.phase = PhaseFunction::henyey_greenstein(g);
  s.radius = 10;
  s.n_outside = 1;
  s.incident = incident;
  s.grid.u_bins = 32;
  s.grid.v_bins = 21;
  s.grid.v_range = 60;
  s.grid.theta_bins = 4;
  s.grid.phi_bins = 7;  // odd: phi = pi lies inside a cell, not on an edge
  return s;
}

PhotonBatchOptions batch(uint64_t photons, uint64_t seed, int threads = 2) {
  return weft::testing::batch_options(photons, seed, threads, 4096);
}

// Sum of BSSRDF * cell area * projected solid angle over cells matching 'keep', i.e. the fraction
// of F_in that exited there.
template <class Keep>
double exited_fraction(const BssrdfTable& t, Keep keep) {
  double s = 0;
  for (int iu = 0; iu < t.grid.u_bins; ++iu)
    for (int iv = 0; iv < t.grid.v_bins; ++iv)
      for (int it = 0; it < t.grid.theta_bins; ++it)
        for (int ip = 0; ip < t.grid.phi_bins; ++ip)
          if (keep(iu, iv, it, ip))
            s +=
                t.value[t.grid.index(iu, iv, it, ip)] * t.cell_area() * t.projected_solid_angle(it);
  return s;
}

// The same with its standard error (a photon lands in one cell: per-cell variances add).
template <class Keep>
MeanEstimate exited_marginal(const BssrdfTable& t, Keep keep) {
  MeanEstimate e;
  double var = 0;
  for (int iu = 0; iu < t.grid.u_bins; ++iu)
    for (int iv = 0; iv < t.grid.v_bins; ++iv)
      for (int it = 0; it < t.grid.theta_bins; ++it)
        for (int ip = 0; ip < t.grid.phi_bins; ++ip)
          if (keep(iu, iv, it, ip)) {
            const size_t k = t.grid.index(iu, iv, it, ip);
            const double scale = t.cell_area() * t.projected_solid_angle(it);
            e.mean += t.value[k] * scale;
            var += std::pow(t.std_error[k] * scale, 2);
          }
  e.std_error = std::sqrt(var);
  return e;
}

}  // namespace

// Index-matched, non-scattering fiber, light along an oblique direction tilted by alpha towards
// the axis: every photon crosses the diameter and leaves at u = pi with axial offset
// -2 r tan(alpha), direction (-sin alpha, 0, cos alpha) in the exit frame. Without absorption
// every photon does exactly that with weight 1, so one cell holds
// BSSRDF = 1 / (B * int cos dw) exactly; with absorption exp(-mu_a 2 r / cos alpha) survive.
TEST(TransportBssrdf, MatchedNonScatteringFiberHitsOneCellExactly) {
  const double alpha = deg_to_rad(20);
  for (double mua : {0.0, 0.01}) {
    BssrdfSetup s = setup(mua, 0, 0, 1.0, {std::sin(alpha), 0, std::cos(alpha)});
    const BssrdfTable t = simulate_bssrdf(s, batch(20000, 1));
    const double weight = std::exp(-mua * 2 * s.radius / std::cos(alpha));
    const int iu = s.grid.u_bins / 2;  // u = pi
    const double v = -2 * s.radius * std::tan(alpha);
    const int iv =
        static_cast<int>(std::floor((v + s.grid.v_range) / (2 * s.grid.v_range) * s.grid.v_bins));
    const int it = static_cast<int>(std::cos(alpha) * s.grid.theta_bins);
    const int ip = static_cast<int>(kPi / (2 * kPi / s.grid.phi_bins));  // phi = pi
    const size_t k = t.grid.index(iu, iv, it, ip);
    const double unit = t.cell_area() * t.projected_solid_angle(it);
    // Everything that exits is in that one cell.
    EXPECT_NEAR(t.value[k] * unit, t.exited.mean, 1e-12);
    EXPECT_NEAR(exited_fraction(t, [](int, int, int, int) { return true; }), t.exited.mean, 1e-12);
    if (mua == 0) {
      EXPECT_NEAR(t.value[k], 1 / unit, 1e-12 / unit);
      EXPECT_EQ(t.std_error[k], 0.0);
      EXPECT_EQ(t.exited.mean, 1.0);
    } else {
      const double se = std::sqrt(weight * (1 - weight) / t.photons);
      EXPECT_NEAR(t.exited.mean, weight, 4 * se);
      EXPECT_NEAR(t.std_error[k] * unit, se, 0.05 * se);  // the reported error is binomial too
    }
    EXPECT_NEAR(t.u_center(iu), kPi, 1e-12);
    EXPECT_LE(std::abs(t.v_center(iv) - v), s.grid.v_range / s.grid.v_bins);
  }
}

// With Fresnel (n = 1.557) at normal incidence photons bounce along the diameter: they leave at
// u = pi after odd passes and back at A (u = 0) after even ones. With T = 1 - R and
// A = exp(-2 mu_a r): opposite (1-R)^2 A / (1 - R^2 A^2), back at A (1-R)^2 R A^2 / (1 - R^2 A^2).
TEST(TransportBssrdf, NormalIncidenceBouncesAlongTheDiameter) {
  const double mua = 0.02, n = 1.557;
  const BssrdfSetup s = setup(mua, 0, 0, n, {0, 0, 1});
  const BssrdfTable t = simulate_bssrdf(s, batch(100000, 2));
  const double r = fresnel_dielectric(1.0, 1.0, n), a = std::exp(-2 * mua * s.radius);
  const double opposite = (1 - r) * (1 - r) * a / (1 - r * r * a * a);
  const double back = (1 - r) * (1 - r) * r * a * a / (1 - r * r * a * a);
  const double got_opposite =
      exited_fraction(t, [&](int iu, int, int, int) { return iu == s.grid.u_bins / 2; });
  const double got_back = exited_fraction(t, [&](int iu, int, int, int) { return iu == 0; });
  // Per-photon exit weights are (1-R) or 0 on each side: binomial errors.
  const double w = 1 - r;
  auto se = [&](double mean) { return std::sqrt(mean * (w - mean) / t.photons); };
  EXPECT_NEAR(got_opposite, opposite, 4 * se(opposite));
  EXPECT_NEAR(got_back, back, 4 * se(back));
  EXPECT_NEAR(got_opposite + got_back, t.exited.mean, 1e-12);
  EXPECT_NEAR(t.specular.mean, r, 1e-12);
}

// A scattering fiber: all exit weight is accounted for (cells + axial overflow), energy closes,
// and at normal incidence the table is mirror-symmetric under b -> -b (u -> -u, phi -> -phi).
TEST(TransportBssrdf, ScatteringFiberEnergyAndMirrorSymmetry) {
  const BssrdfSetup s = setup(0.005, 0.05, 0.8, 1.557, {0, 0, 1});
  const BssrdfTable t = simulate_bssrdf(s, batch(200000, 3));
  const double all = exited_fraction(t, [](int, int, int, int) { return true; });
  EXPECT_NEAR(all + t.overflow, t.exited.mean, 1e-12);
  EXPECT_GT(t.overflow, 0.0);
  EXPECT_NEAR(t.specular.mean + t.exited.mean + t.absorbed.mean + t.roulette.mean + t.lost.mean,
              1.0, 1e-12);
  // Mirror: cell (u, v, theta, phi) <-> (-u, v, theta, -phi). Compare per-u marginals.
  const int nu = s.grid.u_bins, np = s.grid.phi_bins;
  for (int iu = 1; iu < nu / 2; ++iu) {
    const MeanEstimate a = exited_marginal(t, [&](int u, int, int, int) { return u == iu; });
    const MeanEstimate b = exited_marginal(t, [&](int u, int, int, int) { return u == nu - iu; });
    EXPECT_GT(a.std_error, 0.0);
    EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.std_error, b.std_error)) << "u bin " << iu;
  }
  // ... and the azimuth: bins ip <-> np - 1 - ip, over the whole surface.
  for (int ip = 0; ip < np / 2; ++ip) {
    const MeanEstimate a = exited_marginal(t, [&](int, int, int, int p) { return p == ip; });
    const MeanEstimate b =
        exited_marginal(t, [&](int, int, int, int p) { return p == np - 1 - ip; });
    EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.std_error, b.std_error)) << "phi bin " << ip;
  }
  // The mirror must be a real constraint: an oblique light tilted along b breaks it.
  BssrdfSetup tilted = s;
  tilted.incident = normalize(Vec3{0, 0.7, 0.7});
  const BssrdfTable t2 = simulate_bssrdf(tilted, batch(50000, 5));
  const MeanEstimate plus =
      exited_marginal(t2, [&](int u, int, int, int) { return u > 0 && u < nu / 2; });
  const MeanEstimate minus = exited_marginal(t2, [&](int u, int, int, int) { return u > nu / 2; });
  EXPECT_GT(std::abs(plus.mean - minus.mean), 6 * std::hypot(plus.std_error, minus.std_error));
}

TEST(TransportBssrdf, SameBitsAtOneAndTwoThreads) {
  const BssrdfSetup s = setup(0.005, 0.05, 0.8, 1.557, normalize(Vec3{0.3, 0.2, 0.9}));
  const BssrdfTable a = simulate_bssrdf(s, batch(20000, 4, 1));
  const BssrdfTable b = simulate_bssrdf(s, batch(20000, 4, 2));
  ASSERT_EQ(a.value.size(), b.value.size());
  EXPECT_TRUE(a.value == b.value);
  EXPECT_TRUE(a.std_error == b.std_error);
  EXPECT_EQ(a.exited.mean, b.exited.mean);
}

TEST(TransportBssrdf, BadInputIsRejectedWithTheFieldNamed) {
  auto message_of = [](const BssrdfSetup& s) -> std::string {
    try {
      simulate_bssrdf(s, batch(10, 1));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  BssrdfSetup s = setup(0.005, 0.05, 0.8, 1.557, {0, 0, -1});
  EXPECT_NE(message_of(s).find("incident"), std::string::npos);
  s = setup(0.005, 0.05, 0.8, 1.557, {0, 0, 1});
  s.grid.v_range = 0;
  EXPECT_NE(message_of(s).find("v_range"), std::string::npos);
  s = setup(0.005, 0.05, 0.8, 1.557, {0, 0, 1});
  s.grid.theta_bins = 0;
  EXPECT_NE(message_of(s).find("theta_bins"), std::string::npos);
}
