#pragma once
// Gauss-Legendre quadrature.
#include <vector>

namespace weft {

// Nodes (ascending) and weights of the n-point Gauss-Legendre rule on [-1, 1]: closed forms for
// n <= 3, Newton's method on the Legendre recurrence above; exact for polynomials of degree 2n - 1.
void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace weft
