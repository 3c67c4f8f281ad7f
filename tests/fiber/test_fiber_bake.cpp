// Fiber baker: estimator normalization and the agreement of the direct and BSSRDF routes.
// Analytic reference: a fiber whose surface is Lambertian (albedo rho) and whose interior absorbs
// everything has, at every point, f = rho/pi for light and view above the point and 0 otherwise
// (docs/fiber-bsdf.md); the cell averages follow from the cosine-weighted bin areas.
#include <gtest/gtest.h>

#include <cmath>

#include "transport_test_util.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/sphere_mapping.h"
#include "weft/materials/bsdfs.h"
#include "weft/fiber/fiber_bake.h"

using namespace weft;

namespace {

FiberSurfaceModel lambert_surface(double rho) {
  FiberSurfaceModel m;
  m.sample = [rho](const Vec3&, Vec2 u, double, Vec3* w_out, double* weight) {
    *w_out = sample_cosine_hemisphere(u);
    *weight = rho;
    return w_out->z > 0;
  };
  m.albedo = [rho](double) { return rho; };
  return m;
}

// A fiber whose surface is Lambertian (albedo rho) and whose interior absorbs all that enters.
FiberBandPhysics lambert_fiber(double rho) {
  FiberBandPhysics ph;
  ph.surface = lambert_surface(rho);
  ph.interior.geometry = CylinderGeometry(10, 1.0);
  ph.interior.n_inside = 1.557;
  ph.interior.trace = [](const Vec3&, const Vec3&, double w, Rng&, const ExitSink&) {
    PhotonTally t;
    t.photons = 1;
    t.launched = t.absorbed = w;
    return t;
  };
  return ph;
}

// rho / pi where light and view are above the point, else 0 (no bin straddles the horizon).
// A cell pair (i, o) receives about N D_i D_o / pi^2 of the N photons' exits (the Lambert table's
// energy is spread in proportion to D_i D_o), so its relative standard error is about
// 1 / sqrt(that count): each cell must agree within z_max of them.
void expect_lambert_table(const FiberBandTable& t, double rho, double z_max) {
  const DirectionGrid g{t.resolution};
  const auto d = g.cosine_weighted_areas();
  const int cells = g.bins();
  for (int i = 0; i < cells; ++i)
    for (int o = 0; o < cells; ++o) {
      const double got = t.f[static_cast<size_t>(i) * cells + o];
      if (!g.upper(i) || !g.upper(o)) {
        ASSERT_EQ(got, 0.0) << i << " " << o;
        continue;
      }
      const double count = static_cast<double>(t.photons) * d[i] * d[o] / (kPi * kPi);
      const double z = (got / (rho / kPi) - 1) * std::sqrt(count);
      EXPECT_LT(std::abs(z), z_max) << i << " " << o << ": " << got;
    }
}

}  // namespace

TEST(FiberBake, CosineWeightedBinAreasSumToTwoPi) {
  // integral of |cos theta| over the sphere = 2 pi; the per-bin integrals are exact.
  for (int r : {2, 4, 8}) {
    double sum = 0;
    for (double v : DirectionGrid{r}.cosine_weighted_areas()) sum += v;
    EXPECT_NEAR(sum, 2 * kPi, 1e-12) << r;
  }
}

TEST(FiberBake, DirectRouteReproducesLambertSurface) {
  FiberBakeSettings s = weft::testing::bake_settings(4, 400000, 2);
  const double rho = 0.6;
  const auto t = bake_fiber_band_direct(lambert_fiber(rho), s, nullptr);
  EXPECT_EQ(t.photons, s.photons);
  EXPECT_NEAR(t.exit_fraction, rho, 1e-12);  // every photon reflects weight rho exactly
  EXPECT_NEAR(fiber_table_energy(t), kPi * rho, 1e-9);
  // 16 x 16 cells; about 400000 * 0.6 exits over ~64 lit cell pairs -> ~2 % noise per cell.
  expect_lambert_table(t, rho, 4.5);
}

TEST(FiberBake, BssrdfRouteReproducesLambertSurface) {
  FiberBakeSettings s = weft::testing::bake_settings(4, 200000, 2);
  BssrdfRouteSettings grid;
  grid.u_bins = 90;
  const double rho = 0.6;
  const auto t = bake_fiber_band_bssrdf(lambert_fiber(rho), s, grid, nullptr);
  EXPECT_NEAR(t.exit_fraction, rho, 1e-12);
  // The paper's sum over lit cells integrates cos theta_A over each incident table bin with a
  // cq x cq midpoint rule; its error is O(1/cq^2) (measured: a deficit of 1/(4 cq^2), 1e-3 at the
  // default cq = 16), so the energy is pi * rho within 2e-3.
  EXPECT_EQ(grid.cell_quadrature, 16);
  EXPECT_NEAR(fiber_table_energy(t), kPi * rho, 2e-3 * kPi * rho);
  expect_lambert_table(t, rho, 4.5);
}

TEST(FiberBake, BitIdenticalAtOneAndTwoThreads) {
  FiberBakeSettings s = weft::testing::bake_settings(4, 50000, 1);
  s.photons_per_task = 1000;
  const auto a = bake_fiber_band_direct(lambert_fiber(0.5), s, nullptr);
  s.threads = 2;
  const auto b = bake_fiber_band_direct(lambert_fiber(0.5), s, nullptr);
  ASSERT_EQ(a.f.size(), b.f.size());
  for (size_t k = 0; k < a.f.size(); ++k) ASSERT_EQ(a.f[k], b.f[k]) << k;
}

TEST(FiberBake, CancellationKeepsWhatIsDone) {
  FiberBakeSettings s = weft::testing::bake_settings(4, 1000000, 0);
  s.photons_per_task = 1000;
  int calls = 0;
  const auto t = bake_fiber_band_direct(lambert_fiber(0.5), s,
                                        [&](const ProgressUpdate&) { return ++calls < 2; });
  EXPECT_TRUE(t.cancelled);
  EXPECT_GT(t.photons, 0u);
  EXPECT_LT(t.photons, s.photons);
  // What was done is normalized by what was done.
  EXPECT_NEAR(fiber_table_energy(t), kPi * 0.5, 1e-9);
}

TEST(FiberBake, RejectsBadSettings) {
  FiberBakeSettings s;
  s.seed = 1;
  s.photons = 100;
  FiberBandPhysics ph = lambert_fiber(0.5);
  ph.interior.n_inside = 0.5;
  EXPECT_THROW(bake_fiber_band_direct(ph, s, nullptr), Error);
  ph.interior.n_inside = std::nan("");
  EXPECT_THROW(bake_fiber_band_direct(ph, s, nullptr), Error);
  ph = lambert_fiber(0.5);
  ph.interior.trace = nullptr;
  EXPECT_THROW(bake_fiber_band_direct(ph, s, nullptr), Error);
  ph = lambert_fiber(0.5);
  s.resolution = 1;
  EXPECT_THROW(bake_fiber_band_direct(ph, s, nullptr), Error);
  s.resolution = 4;
  s.photons = 0;
  EXPECT_THROW(bake_fiber_band_direct(ph, s, nullptr), Error);
}
