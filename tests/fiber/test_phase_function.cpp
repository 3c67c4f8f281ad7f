#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/fiber/phase_function.h"

using namespace weft;

namespace {
// Sample mean of mu with its standard error.
std::pair<double, double> sampled_mean_cosine(const PhaseFunction& f, int n, uint64_t seed) {
  Rng rng(seed);
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    const double mu = f.sample_cos_theta(rng.uniform());
    s += mu;
    s2 += mu * mu;
  }
  const double mean = s / n;
  return {mean, std::sqrt((s2 / n - mean * mean) / n)};
}
}  // namespace

TEST(PhaseFunction, HenyeyGreensteinMeanCosineIsG) {
  for (double g : {-0.5, 0.0, 0.3, 0.9, 0.99}) {
    const auto f = PhaseFunction::henyey_greenstein(g);
    const auto [mean, se] = sampled_mean_cosine(f, 200000, 1);
    EXPECT_NEAR(mean, g, 5 * se + 1e-12) << "g = " << g;
  }
}

TEST(PhaseFunction, HenyeyGreensteinIsNormalized) {
  const auto f = PhaseFunction::henyey_greenstein(0.8);
  // 2 pi * integral over mu by a fine midpoint rule.
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += f.eval(-1 + (i + 0.5) * 2.0 / n) * 2.0 / n;
  EXPECT_NEAR(2 * kPi * sum, 1.0, 1e-6);
}

TEST(PhaseFunction, TabulatedHgReproducesHgMoments) {
  // A dense table of HG(0.95) must give the analytic mean cosine g and sample it.
  const double g = 0.95;
  const auto hg = PhaseFunction::henyey_greenstein(g);
  std::vector<double> mu, p;
  const int n = 4000;
  for (int i = 0; i <= n; ++i) {
    // Nodes crowd towards mu = 1 where the forward peak is.
    const double t = static_cast<double>(i) / n;
    const double m = 1 - 2 * (1 - t) * (1 - t);
    mu.push_back(m);
    p.push_back(hg.eval(m));
  }
  mu.front() = -1;
  const auto tab = PhaseFunction::tabulated(mu, p);
  EXPECT_NEAR(tab.mean_cosine(), g, 1e-3);
  const auto [mean, se] = sampled_mean_cosine(tab, 200000, 2);
  EXPECT_NEAR(mean, tab.mean_cosine(), 5 * se);
  EXPECT_NEAR(tab.eval(0.3), hg.eval(0.3), 1e-3 * hg.eval(0.3));
}

TEST(PhaseFunction, TabulatedSamplingChiSquare) {
  // A two-segment density p(mu) = 1 + mu (linear) has CDF (mu + 1)^2 / 4.
  const std::vector<double> mu = {-1, 0, 1}, p = {0, 1, 2};
  const auto f = PhaseFunction::tabulated(mu, p);
  Rng rng(3);
  const int bins = 10, n = 100000;
  std::vector<int> counts(bins, 0);
  for (int i = 0; i < n; ++i) {
    const double m = f.sample_cos_theta(rng.uniform());
    ASSERT_GE(m, -1.0);
    ASSERT_LE(m, 1.0);
    counts[std::min(bins - 1, static_cast<int>((m + 1) / 2 * bins))]++;
  }
  double chi2 = 0;
  for (int b = 0; b < bins; ++b) {
    const double a = -1 + 2.0 * b / bins, c = a + 2.0 / bins;
    const double expected = n * ((c + 1) * (c + 1) - (a + 1) * (a + 1)) / 4;
    chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
  }
  EXPECT_LT(chi2, 33.7);  // 99.99 % quantile of chi^2(9)
}

TEST(PhaseFunction, RejectsBadInput) {
  EXPECT_THROW(PhaseFunction::henyey_greenstein(1.0), Error);
  EXPECT_THROW(PhaseFunction::henyey_greenstein(std::nan("")), Error);
  const std::vector<double> mu = {-1, 1}, bad = {1, -1};
  EXPECT_THROW(PhaseFunction::tabulated(mu, bad), Error);
  const std::vector<double> short_mu = {-0.5, 1}, ok = {1, 1};
  EXPECT_THROW(PhaseFunction::tabulated(short_mu, ok), Error);
}
