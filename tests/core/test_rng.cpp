#include <gtest/gtest.h>

#include <set>

#include "weft/core/rng.h"

using weft::Rng;

TEST(Rng, SameSeedAndTaskGiveSameStream) {
  Rng a(7, 3, 1), b(7, 3, 1);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.next_u32(), b.next_u32());
}

TEST(Rng, DistinctTasksGiveDistinctStreams) {
  std::set<uint32_t> firsts;
  for (uint64_t task = 0; task < 1000; ++task) firsts.insert(Rng(1, task).next_u32());
  // 1000 draws from 2^32 values: a collision has probability ~1e-4.
  EXPECT_GE(firsts.size(), 999u);
}

TEST(Rng, UniformIsInUnitIntervalWithCorrectMoments) {
  Rng r(42);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  // Mean 1/2 with sd sqrt(1/12/n) = 6.5e-4; variance 1/12. 5-sigma bounds.
  EXPECT_NEAR(sum / n, 0.5, 5 * 6.5e-4);
  EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 2e-3);
}
