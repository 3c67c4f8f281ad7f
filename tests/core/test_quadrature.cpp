// Gauss-Legendre quadrature against Abramowitz & Stegun, Handbook of Mathematical Functions
// (1964): Table 25.4 (abscissas and weights, 15 decimals) and eq. 25.4.30 (the error term).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/quadrature.h"

using namespace weft;

namespace {

// Integral of x^k over [-1, 1] by the n-point rule.
double rule_moment(int n, int k) {
  std::vector<double> x, w;
  gauss_legendre(n, x, w);
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += w[i] * std::pow(x[i], k);
  return sum;
}

double exact_moment(int k) {
  return k % 2 ? 0.0 : 2.0 / (k + 1);
}

}  // namespace

TEST(GaussLegendre, NodesAndWeightsMatchAbramowitzStegunTable25_4) {
  // A&S Table 25.4, the positive abscissas x_i and weights w_i (the rule is symmetric).
  struct Row {
    int n;
    std::vector<double> x, w;
  };
  const Row rows[] = {
      {2, {0.577350269189626}, {1.0}},
      {3, {0.0, 0.774596669241483}, {0.888888888888889, 0.555555555555556}},
      {4, {0.339981043584856, 0.861136311594053}, {0.652145154862546, 0.347854845137454}},
      {5,
       {0.0, 0.538469310105683, 0.906179845938664},
       {0.568888888888889, 0.478628670499366, 0.236926885056189}},
  };
  for (const auto& row : rows) {
    std::vector<double> x, w;
    gauss_legendre(row.n, x, w);
    ASSERT_EQ(x.size(), static_cast<size_t>(row.n));
    ASSERT_EQ(w.size(), static_cast<size_t>(row.n));
    for (int i = 1; i < row.n; ++i) EXPECT_LT(x[i - 1], x[i]) << "ascending, n " << row.n;
    // The table's positive half is the upper end of our ascending list, from the middle out.
    const int first = row.n / 2;
    for (size_t k = 0; k < row.x.size(); ++k) {
      const int i = first + static_cast<int>(k);
      // 15 decimals: half a unit of the last place is 5e-16.
      EXPECT_NEAR(x[i], row.x[k], 1e-15) << "n " << row.n << " node " << i;
      EXPECT_NEAR(w[i], row.w[k], 1e-15) << "n " << row.n << " weight " << i;
      EXPECT_EQ(x[row.n - 1 - i], -x[i]);
      EXPECT_EQ(w[row.n - 1 - i], w[i]);
    }
  }
}

TEST(GaussLegendre, ExactUpToDegreeTwoNMinusOne) {
  for (int n = 1; n <= 24; ++n)
    for (int k = 0; k <= 2 * n - 1; ++k)
      EXPECT_NEAR(rule_moment(n, k), exact_moment(k), 2e-15) << "n " << n << " degree " << k;
}

TEST(GaussLegendre, ErrorAtDegreeTwoNIsTheTabulatedTerm) {
  // A&S 25.4.30: int f - sum w_i f(x_i) = 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^3) f^(2n)(xi); for
  // f = x^(2n), f^(2n) = (2n)!, so the rule misses x^(2n) by 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^2).
  for (int n = 1; n <= 8; ++n) {
    const double fact_n = std::tgamma(n + 1.0), fact_2n = std::tgamma(2 * n + 1.0);
    const double expected =
        std::pow(2.0, 2 * n + 1) * std::pow(fact_n, 4) / ((2 * n + 1) * fact_2n * fact_2n);
    const double error = exact_moment(2 * n) - rule_moment(n, 2 * n);
    EXPECT_NEAR(error, expected, 1e-12 * expected + 1e-15) << "n " << n;
  }
}

TEST(GaussLegendre, RejectsNoNodes) {
  std::vector<double> x, w;
  EXPECT_THROW(gauss_legendre(0, x, w), Error);
  EXPECT_THROW(gauss_legendre(-3, x, w), Error);
}
