#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "weft/core/distribution.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"

using namespace weft;

TEST(Distribution1D, PdfIntegratesToOneAndMatchesWeights) {
  const std::vector<double> w = {1, 0, 3, 4};
  Distribution1D d(w);
  EXPECT_DOUBLE_EQ(d.integral(), 2.0);  // mean of the weights
  EXPECT_DOUBLE_EQ(d.pmf(0), 1.0 / 8);
  EXPECT_DOUBLE_EQ(d.pmf(1), 0.0);
  EXPECT_DOUBLE_EQ(d.pdf(0.6), 4 * 3.0 / 8);
}

TEST(Distribution1D, SamplingFollowsWeightsChiSquare) {
  const std::vector<double> w = {1, 0, 3, 4, 0.5, 2};
  Distribution1D d(w);
  Rng rng(3);
  const int n = 100000;
  std::vector<int> counts(w.size(), 0);
  for (int i = 0; i < n; ++i) {
    const auto s = d.sample_continuous(rng.uniform());
    ASSERT_GE(s.x, 0.0);
    ASSERT_LT(s.x, 1.0);
    ASSERT_EQ(s.bin, d.bin_of(s.x));
    ASSERT_NEAR(s.pdf, d.pdf(s.x), 1e-12);
    ASSERT_GT(s.pdf, 0.0);
    counts[s.bin]++;
  }
  EXPECT_EQ(counts[1], 0);
  double chi2 = 0;
  int dof = -1;
  for (size_t i = 0; i < w.size(); ++i) {
    const double expected = n * d.pmf(i);
    if (expected > 0) {
      chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
      ++dof;
    }
  }
  // dof = 4; the 99.99 % quantile of chi^2(4) is 23.5.
  EXPECT_LT(chi2, 23.5);
}

TEST(Distribution1D, RejectsNegativeAndNonFiniteWeights) {
  const std::vector<double> neg = {1, -1};
  EXPECT_THROW(Distribution1D{neg}, Error);
  const std::vector<double> nan = {1, std::nan("")};
  EXPECT_THROW(Distribution1D{nan}, Error);
}

TEST(Distribution2D, PdfMatchesNormalizedWeights) {
  const std::vector<double> w = {1, 2, 3, 0, 0, 6};  // 3 x 2
  Distribution2D d(w, 3, 2);
  const double mean = 12.0 / 6;
  EXPECT_NEAR(d.pdf({0.5, 0.25}), 2 / mean, 1e-12);
  EXPECT_NEAR(d.pdf({0.9, 0.75}), 6 / mean, 1e-12);
  EXPECT_NEAR(d.pdf({0.1, 0.75}), 0.0, 1e-12);
  Rng rng(5);
  for (int i = 0; i < 1000; ++i) {
    const auto s = d.sample({rng.uniform(), rng.uniform()});
    ASSERT_NEAR(s.pdf, d.pdf(s.p), 1e-9);
    ASSERT_GT(s.pdf, 0.0);
  }
}
