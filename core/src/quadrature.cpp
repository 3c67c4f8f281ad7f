#include "weft/core/quadrature.h"

#include <cmath>
#include <utility>

#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {
namespace {

// P_n(z) and P_n'(z) by the three-term recurrence.
std::pair<double, double> legendre_and_derivative(int n, double z) {
  double p0 = 1, p1 = z;
  for (int k = 2; k <= n; ++k) {
    const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return {p1, n * (z * p1 - p0) / (z * z - 1)};
}

}  // namespace

void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1) throw Error("", "n", "Gauss-Legendre needs at least one node");
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  // The smallest rules in closed form, correctly rounded (Newton's weights are off by a few ulp).
  if (n == 1) {
    weights[0] = 2;
    return;
  }
  if (n == 2) {
    nodes = {-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
    weights = {1.0, 1.0};
    return;
  }
  if (n == 3) {
    nodes = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
    weights = {5.0 / 9, 8.0 / 9, 5.0 / 9};
    return;
  }
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));  // initial guess for the i-th root
    for (int it = 0; it < 100; ++it) {
      const auto [p, dp] = legendre_and_derivative(n, z);
      const double dz = p / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    // The weight needs P_n' at the converged root: the derivative from before the last Newton
    // step is off by P_n'' dz, which for n = 3 already costs 5e-15 of the weight.
    const double dp = legendre_and_derivative(n, z).second;
    nodes[i] = -z;
    nodes[n - 1 - i] = z;
    weights[i] = weights[n - 1 - i] = 2 / ((1 - z * z) * dp * dp);
  }
}

}  // namespace weft
