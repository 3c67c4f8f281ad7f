// The fiber BSSRDF (bssrdf.h): normalization (units), exact non-scattering cases, symmetry and
// energy bookkeeping, on the smooth-Fresnel fiber of the paper's section 3.1.
#include <gtest/gtest.h>

#include <cmath>

#include "transport_test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fiber/bssrdf.h"
#include "weft/materials/fresnel.h"

using namespace weft;

namespace {

constexpr double kRadius = 10;

FiberBandPhysics fiber(double mua, double mus, double g, double n) {
  return smooth_fiber_physics(weft::testing::hg_medium(mua, mus, g, n), kRadius, 1.0);
}

// The subsurface BSSRDF with standard errors, on an odd direction grid (R = 5: the plane y = 0
// of an exit direction lies inside a bin, not on an edge).
BssrdfGrid grid() {
  return {.u_bins = 32,
          .v_bins = 21,
          .v_range = 60,
          .direction_resolution = 5,
          .surface_in_table = false,
          .keep_squares = true};
}

TaskBatch bssrdf_batch(uint64_t photons, uint64_t seed, int threads = 2) {
  return weft::testing::batch_options(photons, seed, threads, 4096);
}

double fraction(const BssrdfResult& r, double weight) {
  return weight / r.books.launched;
}

// Fraction of F_in that exited through cells matching keep(iu, iv, direction bin), with its
// standard error. A photon leaves through at most one cell (surface reflections are not binned),
// so the summed per-cell moments are the moments of the marginal.
template <class Keep>
MeanEstimate exited(const BssrdfResult& r, Keep keep) {
  double s = 0, s2 = 0;
  const int dirs = r.grid.directions().bins();
  for (int iu = 0; iu < r.grid.u_bins; ++iu)
    for (int iv = 0; iv < r.grid.v_bins; ++iv)
      for (int o = 0; o < dirs; ++o)
        if (keep(iu, iv, o)) {
          const size_t k = r.grid.index(iu, iv, o);
          s += r.exit_weight[k];
          s2 += r.exit_weight2[k];
        }
  return MeanAccumulator{s, s2}.estimate(r.photons_in[0]);
}

const auto all_cells = [](int, int, int) { return true; };

}  // namespace

// Index-matched, non-scattering fiber, light along an oblique direction tilted by alpha towards
// the axis: every photon crosses the diameter and leaves at u = pi with axial offset
// -2 r tan(alpha), direction (-sin alpha, 0, cos alpha) in the exit frame. Without absorption
// every photon does exactly that with weight 1, so one cell holds BSSRDF = 1 / (B D_o) exactly;
// with absorption exp(-mu_a 2 r / cos alpha) survive.
TEST(Bssrdf, MatchedNonScatteringFiberHitsOneCellExactly) {
  const double alpha = deg_to_rad(20);
  for (double mua : {0.0, 0.01}) {
    const BssrdfGrid g = grid();
    const BssrdfResult r = simulate_bssrdf(
        fiber(mua, 0, 0, 1.0), g, BssrdfIncidence::from({std::sin(alpha), 0, std::cos(alpha)}),
        bssrdf_batch(20000, 1));
    const double weight = std::exp(-mua * 2 * kRadius / std::cos(alpha));
    const int iu = g.u_bins / 2;  // u = pi
    const double v = -2 * kRadius * std::tan(alpha);
    const int iv = static_cast<int>(std::floor((v + g.v_range) / (2 * g.v_range) * g.v_bins));
    const int o = g.directions().bin_of({-std::sin(alpha), 0, std::cos(alpha)});
    const MeanEstimate all = exited(r, all_cells);
    const MeanEstimate one =
        exited(r, [&](int u, int w, int d) { return u == iu && w == iv && d == o; });
    // Everything that exits is in that one cell.
    EXPECT_NEAR(one.mean, all.mean, 1e-12);
    EXPECT_NEAR(all.mean, fraction(r, r.books.exited), 1e-12);
    const double d_o = g.directions().cosine_weighted_areas()[o];
    const MeanEstimate value = r.value(0, iu, iv, o);
    if (mua == 0) {
      EXPECT_NEAR(value.mean, 1 / (r.cell_area() * d_o), 1e-12 / (r.cell_area() * d_o));
      EXPECT_EQ(value.std_error, 0.0);
      EXPECT_EQ(all.mean, 1.0);
    } else {
      const double se = std::sqrt(weight * (1 - weight) / r.photons_in[0]);
      EXPECT_NEAR(all.mean, weight, 4 * se);
      // The reported error is binomial too.
      EXPECT_NEAR(value.std_error * r.cell_area() * d_o, se, 0.05 * se);
    }
    EXPECT_NEAR(g.u_center(iu), kPi, 1e-12);
    EXPECT_LE(std::abs(g.v_center(iv) - v), g.v_range / g.v_bins);
  }
}

// With Fresnel (n = 1.557) at normal incidence photons bounce along the diameter: they leave at
// u = pi after odd passes and back at A (u = 0) after even ones. With T = 1 - R and
// A = exp(-2 mu_a r): opposite (1-R)^2 A / (1 - R^2 A^2), back at A (1-R)^2 R A^2 / (1 - R^2 A^2)
// (a geometric series of the passes).
TEST(Bssrdf, NormalIncidenceBouncesAlongTheDiameter) {
  const double mua = 0.02, n = 1.557;
  const BssrdfGrid g = grid();
  const BssrdfResult r = simulate_bssrdf(fiber(mua, 0, 0, n), g, BssrdfIncidence::from({0, 0, 1}),
                                         bssrdf_batch(100000, 2));
  const double rf = fresnel_dielectric(1.0, 1.0, n), a = std::exp(-2 * mua * kRadius);
  const double opposite = (1 - rf) * (1 - rf) * a / (1 - rf * rf * a * a);
  const double back = (1 - rf) * (1 - rf) * rf * a * a / (1 - rf * rf * a * a);
  const MeanEstimate got_opposite = exited(r, [&](int iu, int, int) { return iu == g.u_bins / 2; });
  const MeanEstimate got_back = exited(r, [&](int iu, int, int) { return iu == 0; });
  EXPECT_TRUE(weft::testing::within_sigma(got_opposite, opposite, 4));
  EXPECT_TRUE(weft::testing::within_sigma(got_back, back, 4));
  EXPECT_NEAR(got_opposite.mean + got_back.mean, fraction(r, r.books.exited), 1e-12);
  // The surface reflection is booked, not binned: exactly R per photon.
  EXPECT_NEAR(fraction(r, r.books.specular), rf, 1e-12);
  EXPECT_NEAR(fraction(r, r.books.specular_excess), 0.0, 1e-15);
}

// A scattering fiber: all exit weight is accounted for (cells + axial overflow), energy closes,
// and at normal incidence the table is mirror-symmetric under b -> -b (u -> -u, direction
// y -> -y).
TEST(Bssrdf, ScatteringFiberEnergyAndMirrorSymmetry) {
  const BssrdfGrid g = grid();
  const FiberBandPhysics ph = fiber(0.005, 0.05, 0.8, 1.557);
  const BssrdfResult r =
      simulate_bssrdf(ph, g, BssrdfIncidence::from({0, 0, 1}), bssrdf_batch(200000, 3));
  const double all = exited(r, all_cells).mean;
  EXPECT_NEAR(all + fraction(r, r.overflow), fraction(r, r.books.exited), 1e-12);
  EXPECT_GT(r.overflow, 0.0);
  EXPECT_NEAR(r.books.imbalance(), 0.0, 1e-9 * r.books.launched);
  // Mirror: cell (u, v, d) <-> (-u, v, mirror_y(d)). Compare per-u marginals ...
  const int nu = g.u_bins;
  const DirectionGrid dirs = g.directions();
  for (int iu = 1; iu < nu / 2; ++iu) {
    const MeanEstimate a = exited(r, [&](int u, int, int) { return u == iu; });
    const MeanEstimate b = exited(r, [&](int u, int, int) { return u == nu - iu; });
    EXPECT_GT(a.std_error, 0.0);
    EXPECT_TRUE(weft::testing::within_sigma(a, b.mean, 4.5, b.std_error)) << "u bin " << iu;
  }
  // ... and per exit-direction marginals over the whole surface.
  for (int d = 0; d < dirs.bins(); ++d) {
    const int m = dirs.mirrored_bin(d, 1);
    if (m <= d) continue;
    const MeanEstimate a = exited(r, [&](int, int, int o) { return o == d; });
    const MeanEstimate b = exited(r, [&](int, int, int o) { return o == m; });
    if (a.mean == 0 && b.mean == 0) {
      // Only bins below the exit point's horizon stay empty.
      EXPECT_FALSE(dirs.upper(d)) << "direction " << d;
      continue;
    }
    EXPECT_TRUE(weft::testing::within_sigma(a, b.mean, 4.5, b.std_error)) << "direction " << d;
  }
  // The mirror must be a real constraint: an oblique light tilted along b breaks it.
  const BssrdfResult t = simulate_bssrdf(ph, g, BssrdfIncidence::from(normalize(Vec3{0, 0.7, 0.7})),
                                         bssrdf_batch(50000, 5));
  const MeanEstimate plus = exited(t, [&](int u, int, int) { return u > 0 && u < nu / 2; });
  const MeanEstimate minus = exited(t, [&](int u, int, int) { return u > nu / 2; });
  EXPECT_GT(std::abs(plus.mean - minus.mean), 6 * std::hypot(plus.std_error, minus.std_error));
}

TEST(Bssrdf, SameBitsAtOneAndTwoThreads) {
  const FiberBandPhysics ph = fiber(0.005, 0.05, 0.8, 1.557);
  const BssrdfIncidence in = BssrdfIncidence::from(normalize(Vec3{0.3, 0.2, 0.9}));
  const BssrdfResult a = simulate_bssrdf(ph, grid(), in, bssrdf_batch(20000, 4, 1));
  const BssrdfResult b = simulate_bssrdf(ph, grid(), in, bssrdf_batch(20000, 4, 2));
  ASSERT_EQ(a.exit_weight.size(), b.exit_weight.size());
  EXPECT_TRUE(a.exit_weight == b.exit_weight);
  EXPECT_TRUE(a.exit_weight2 == b.exit_weight2);
  EXPECT_EQ(a.books.exited, b.books.exited);
  // Binned incidence (the baker's) too.
  BssrdfGrid g = grid();
  g.v_bins = 1;
  g.v_range = kTransportInfinity;
  const BssrdfResult c =
      simulate_bssrdf(ph, g, BssrdfIncidence::binned(4, 4), bssrdf_batch(20000, 4, 1));
  const BssrdfResult d =
      simulate_bssrdf(ph, g, BssrdfIncidence::binned(4, 4), bssrdf_batch(20000, 4, 2));
  EXPECT_TRUE(c.exit_weight == d.exit_weight);
  EXPECT_TRUE(c.flux_in == d.flux_in);
}

TEST(Bssrdf, BinnedIncidenceCoversTheLitHemisphereWithFluxCosine) {
  // Photons visit the (s, psi) bins in turn, uniformly in solid angle within a bin, each carrying
  // flux cos theta_A. Over a whole bin row the mean flux is the hemisphere's int cos / 2 pi = 1/2;
  // per bin it is the bin's mean cosine.
  const FiberBandPhysics ph = fiber(0.005, 0.05, 0.8, 1.557);
  BssrdfGrid g;
  g.u_bins = 8;
  g.direction_resolution = 2;
  const int ns = 4, npsi = 3;
  const BssrdfResult r =
      simulate_bssrdf(ph, g, BssrdfIncidence::binned(ns, npsi), bssrdf_batch(120000, 7));
  double flux = 0;
  uint64_t n = 0;
  for (int b = 0; b < ns * npsi; ++b) {
    EXPECT_EQ(r.photons_in[b], 120000u / (ns * npsi));
    flux += r.flux_in[b];
    n += r.photons_in[b];
  }
  // Mean of cos theta over the hemisphere, uniform in solid angle: 1/2 (Monte Carlo, 4 sigma of
  // the cosine's standard deviation 1/sqrt(12) over n photons).
  EXPECT_NEAR(flux / n, 0.5, 4 / std::sqrt(12.0 * n));
  EXPECT_NEAR(r.books.launched, flux, 1e-9 * flux);
}

TEST(Bssrdf, BadInputIsRejectedWithTheFieldNamed) {
  auto message_of = [](const BssrdfGrid& g, const BssrdfIncidence& in) {
    return weft::testing::error_of(
        [&] { simulate_bssrdf(fiber(0.005, 0.05, 0.8, 1.557), g, in, bssrdf_batch(10, 1)); });
  };
  const BssrdfIncidence normal = BssrdfIncidence::from({0, 0, 1});
  EXPECT_NE(message_of(grid(), BssrdfIncidence::from({0, 0, -1})).find("incident"),
            std::string::npos);
  BssrdfGrid g = grid();
  g.v_range = 0;
  EXPECT_NE(message_of(g, normal).find("v_range"), std::string::npos);
  g = grid();
  g.direction_resolution = 0;
  EXPECT_NE(message_of(g, normal).find("direction_resolution"), std::string::npos);
  g = grid();
  g.u_bins = 31;
  EXPECT_NE(message_of(g, normal).find("u_bins"), std::string::npos);
  g = grid();
  g.v_range = kTransportInfinity;  // an infinite window has one cell
  EXPECT_NE(message_of(g, normal).find("v_bins"), std::string::npos);
  EXPECT_NE(message_of(grid(), BssrdfIncidence::binned(0, 4)).find("incident_bins"),
            std::string::npos);
}
