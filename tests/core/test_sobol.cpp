#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/sobol.h"

namespace weft {
namespace {

// Points 0 .. 2^m - 1 of a Sobol' sequence form a (t, m, s)-net (Joe and Kuo 2008): every
// dimension alone is a (0, m, 1)-net, one point per interval of length 2^-m, and the first two
// dimensions a (0, m, 2)-net, one point per elementary box of area 2^-m. Owen scrambling and a
// digital shift keep both (each permutes the elementary intervals).
void expect_stratified(const std::function<double(uint32_t, int)>& point, int m) {
  const uint32_t n = 1u << m;
  for (int d = 0; d < ScrambledSobol::kDimensions; ++d) {
    std::vector<int> hits(n, 0);
    for (uint32_t i = 0; i < n; ++i) {
      const double x = point(i, d);
      ASSERT_GE(x, 0.0);
      ASSERT_LT(x, 1.0);
      ++hits[static_cast<size_t>(x * n)];
    }
    for (uint32_t k = 0; k < n; ++k) EXPECT_EQ(hits[k], 1) << "dim " << d << " interval " << k;
  }
  for (int a = 0; a <= m; ++a) {  // boxes of 2^a x 2^(m - a)
    std::vector<int> hits(n, 0);
    for (uint32_t i = 0; i < n; ++i) {
      const auto x = static_cast<uint32_t>(point(i, 0) * (1u << a));
      const auto y = static_cast<uint32_t>(point(i, 1) * (1u << (m - a)));
      ++hits[(x << (m - a)) | y];
    }
    for (uint32_t k = 0; k < n; ++k) EXPECT_EQ(hits[k], 1) << "boxes 2^" << a << " box " << k;
  }
}

TEST(ScrambledSobol, TheSequenceIsANet) {
  expect_stratified([](uint32_t i, int d) { return ScrambledSobol::sobol_bits(i, d) * 0x1.0p-32; },
                    8);
  // Joe and Kuo's third dimension (d = 3, m_1 = 1, m_2 = 3): point 1 is m_1 / 2 = 1/2, point 2 is
  // m_2 / 4 = 3/4, point 3 their digital sum 1/4.
  EXPECT_EQ(ScrambledSobol::sobol_bits(1, 2), 0x80000000u);
  EXPECT_EQ(ScrambledSobol::sobol_bits(2, 2), 0xc0000000u);
  EXPECT_EQ(ScrambledSobol::sobol_bits(3, 2), 0x40000000u);
  EXPECT_THROW(ScrambledSobol::sobol_bits(1, ScrambledSobol::kDimensions), Error);
}

TEST(ScrambledSobol, ScrambledPointsStayStratified) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    Rng rng(seed, 7);
    const ScrambledSobol sobol(rng);
    expect_stratified([&](uint32_t i, int d) { return sobol.sample(i, d); }, 10);
  }
}

// Unbiased: one point, over independent scrambles, is uniform. Over 20 000 scrambles the mean of
// point 5 lies within 4.5 standard errors (sqrt(1/12 / 20 000)) of 1/2 in every dimension, and the
// fraction in each quarter within 4.5 standard errors (sqrt(3/16 / 20 000)) of 1/4.
TEST(ScrambledSobol, EveryPointIsUniform) {
  const int n = 20000;
  for (int d = 0; d < ScrambledSobol::kDimensions; ++d) {
    double sum = 0;
    int quarter[4] = {0, 0, 0, 0};
    for (int k = 0; k < n; ++k) {
      Rng rng(11, static_cast<uint64_t>(k));
      const double x = ScrambledSobol(rng).sample(5, d);
      sum += x;
      ++quarter[static_cast<int>(x * 4)];
    }
    EXPECT_NEAR(sum / n, 0.5, 4.5 * std::sqrt(1.0 / 12 / n)) << d;
    for (int q = 0; q < 4; ++q)
      EXPECT_NEAR(quarter[q] / double(n), 0.25, 4.5 * std::sqrt(3.0 / 16 / n)) << d << " " << q;
  }
}

TEST(ScrambledSobol, SameStreamSamePoints) {
  Rng a(3, 4), b(3, 4), c(3, 5);
  const ScrambledSobol sa(a), sb(b), sc(c);
  EXPECT_EQ(sa.sample(17, 3), sb.sample(17, 3));
  EXPECT_NE(sa.sample(17, 3), sc.sample(17, 3));
}

}  // namespace
}  // namespace weft
