// The tables' direction grid (core/direction_grid.h): bins round-trip, cover equal solid angles,
// never straddle the horizon, interpolate only within their hemisphere, carry exact cosine-
// weighted areas, and respect the three mirror symmetries.
#include <gtest/gtest.h>

#include <cmath>

#include "weft/core/direction_grid.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"

using namespace weft;

namespace {

Vec3 uniform_direction(Rng& rng) {
  const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
  const double s = std::sqrt(1 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}

}  // namespace

TEST(DirectionGrid, ChartRoundTripsAndBinsRoundTrip) {
  Rng rng(3);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 d = uniform_direction(rng);
    const Vec3 back = DirectionGrid::to_direction(DirectionGrid::to_chart(d));
    ASSERT_LT(length(back - d), 1e-12) << d;
  }
  for (int r : {1, 2, 7, 16}) {
    const DirectionGrid g{r};
    EXPECT_EQ(g.bins(), 2 * r * r);
    for (int b = 0; b < g.bins(); ++b) EXPECT_EQ(g.bin_of(g.bin_center(b)), b);
  }
}

TEST(DirectionGrid, BinsCoverEqualSolidAngles) {
  // Uniform directions fill the 2 R^2 bins evenly (each 2 pi / R^2), within 5 binomial sigma.
  const DirectionGrid g{4};
  std::vector<int> counts(g.bins(), 0);
  Rng rng(1);
  const int n = 320000;
  for (int i = 0; i < n; ++i) ++counts[g.bin_of(uniform_direction(rng))];
  const double expect = static_cast<double>(n) / g.bins();
  for (int c : counts) EXPECT_NEAR(c, expect, 5 * std::sqrt(expect));
  EXPECT_DOUBLE_EQ(g.bin_solid_angle() * g.bins(), 4 * kPi);
}

TEST(DirectionGrid, NoBinStraddlesTheHorizon) {
  // Every point of an upper bin has z >= 0, every point of a lower bin z <= 0 (checked on a
  // 33 x 33 lattice per bin, edges included: there z may be 0 to rounding).
  for (int r : {1, 3, 8}) {
    const DirectionGrid g{r};
    for (int b = 0; b < g.bins(); ++b)
      for (int i = 0; i <= 32; ++i)
        for (int j = 0; j <= 32; ++j) {
          const Vec3 d = DirectionGrid::to_direction(g.chart_point(b, i / 32.0, j / 32.0));
          if (g.upper(b))
            ASSERT_GE(d.z, -1e-15) << b;
          else
            ASSERT_LE(d.z, 1e-15) << b;
        }
  }
  // Directions exactly on the horizon belong to the upper hemisphere.
  EXPECT_TRUE(DirectionGrid{4}.upper(DirectionGrid{4}.bin_of({1, 0, 0})));
}

TEST(DirectionGrid, CosineWeightedAreasAreExact) {
  // Against a 400 x 400 midpoint rule per bin (|cos| has kinks along the square's diagonals, so
  // the rule's error is ~1e-5 of a whole hemisphere); sum D_k = 2 pi, the integral of |cos theta|
  // over the sphere; and one bin per hemisphere holds pi.
  EXPECT_NEAR(DirectionGrid{1}.cosine_weighted_areas()[0], kPi, 1e-14);
  for (int r : {1, 3, 4}) {
    const DirectionGrid g{r};
    const auto d = g.cosine_weighted_areas();
    double sum = 0;
    for (double v : d) sum += v;
    EXPECT_NEAR(sum, 2 * kPi, 1e-12) << r;
    const int q = 400;
    for (int b = 0; b < g.bins(); ++b) {
      double acc = 0;
      for (int i = 0; i < q; ++i)
        for (int j = 0; j < q; ++j)
          acc += std::abs(
              DirectionGrid::to_direction(g.chart_point(b, (i + 0.5) / q, (j + 0.5) / q)).z);
      EXPECT_NEAR(d[b], acc * g.bin_solid_angle() / (q * q), 2e-5 * d[b] + 1e-7) << r << " " << b;
    }
  }
}

TEST(DirectionGrid, BilinearStaysInItsHemisphereAndIsContinuousWithinIt) {
  const DirectionGrid g{8};
  Rng rng(5);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 d = uniform_direction(rng);
    const auto fp = g.bilinear(DirectionGrid::to_chart(d));
    double wsum = 0;
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(g.upper(fp.bin[k]), d.z >= 0);
      EXPECT_GE(fp.weight[k], 0.0);
      wsum += fp.weight[k];
    }
    EXPECT_NEAR(wsum, 1.0, 1e-12);
  }
  // Continuity: a smooth function sampled at bin centres and interpolated changes little
  // between nearby directions of one hemisphere.
  auto f = [&](const Vec3& d) {
    const auto fp = g.bilinear(DirectionGrid::to_chart(d));
    double v = 0;
    for (int k = 0; k < 4; ++k) v += fp.weight[k] * g.bin_center(fp.bin[k]).x;
    return v;
  };
  for (int i = 0; i < 2000; ++i) {
    Vec3 d = uniform_direction(rng);
    d.z = std::abs(d.z) + 0.05;
    d = normalize(d);
    const Vec3 e = normalize(d + Vec3{1e-6, -1e-6, 1e-6});
    EXPECT_LT(std::abs(f(d) - f(e)), 1e-4);
  }
}

TEST(DirectionGrid, MirroredBinsHoldTheMirroredDirections) {
  Rng rng(9);
  for (int r : {1, 4, 5}) {
    const DirectionGrid g{r};
    for (int i = 0; i < 5000; ++i) {
      const Vec3 d = uniform_direction(rng);
      const int b = g.bin_of(d);
      EXPECT_EQ(g.mirrored_bin(b, 0), g.bin_of({-d.x, d.y, d.z}));
      EXPECT_EQ(g.mirrored_bin(b, 1), g.bin_of({d.x, -d.y, d.z}));
      if (d.z != 0) {
        EXPECT_EQ(g.mirrored_bin(b, 2), g.bin_of({d.x, d.y, -d.z}));
      }
    }
  }
}
