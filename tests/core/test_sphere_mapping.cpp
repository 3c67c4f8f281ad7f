#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"

using namespace weft;

TEST(EqualAreaMapping, RoundTripsAndGivesUnitVectors) {
  Rng rng(11);
  for (int i = 0; i < 20000; ++i) {
    const Vec2 p{rng.uniform(), rng.uniform()};
    const Vec3 d = equal_area_square_to_sphere(p);
    ASSERT_NEAR(length(d), 1.0, 1e-12);
    const Vec2 q = equal_area_sphere_to_square(d);
    ASSERT_NEAR(p.x, q.x, 1e-9);
    ASSERT_NEAR(p.y, q.y, 1e-9);
  }
}

TEST(EqualAreaMapping, CellsHaveEqualSolidAngle) {
  // Uniform directions on the sphere must land uniformly on the square: chi^2 over 8x8 cells.
  Rng rng(12);
  const int n = 8, samples = 256000;
  std::vector<int> counts(n * n, 0);
  for (int i = 0; i < samples; ++i) {
    const double z = 1 - 2 * rng.uniform();
    const double phi = 2 * kPi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec2 p = equal_area_sphere_to_square({r * std::cos(phi), r * std::sin(phi), z});
    const int ix = std::min(n - 1, static_cast<int>(p.x * n));
    const int iy = std::min(n - 1, static_cast<int>(p.y * n));
    counts[iy * n + ix]++;
  }
  const double expected = static_cast<double>(samples) / (n * n);
  double chi2 = 0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  // 63 dof; the 99.99 % quantile of chi^2(63) is about 113.
  EXPECT_LT(chi2, 113.0);
}

TEST(EqualAreaMapping, PolesAndHemispheres) {
  const Vec3 up = equal_area_square_to_sphere({0.5, 0.5});
  EXPECT_NEAR(up.z, 1.0, 1e-12);
  const Vec3 down = equal_area_square_to_sphere({0.0, 0.0});
  EXPECT_NEAR(down.z, -1.0, 1e-12);
}
