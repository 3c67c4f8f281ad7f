#pragma once
// Phase functions for photon transport: Henyey-Greenstein (MCML's convention) and tabulated ones
// (Mie). Normalization: integral of p over the sphere = 1, so p = 1/(4 pi) is isotropic.
#include <span>
#include <vector>

#include "weft/core/rng.h"
#include "weft/core/vec.h"

namespace weft {

class PhaseFunction {
 public:
  // Henyey-Greenstein with asymmetry g in (-1, 1).
  static PhaseFunction henyey_greenstein(double g);
  // Tabulated p(mu) at nodes mu (strictly increasing, from -1 to 1), piecewise linear in mu
  // between nodes. Values are normalized here; they must be >= 0 and finite. Put nodes densely
  // where p varies fast (the forward peak of large particles): sampling is exact for the
  // piecewise-linear function, so its accuracy is that of the node grid.
  static PhaseFunction tabulated(std::span<const double> mu, std::span<const double> p);

  // Samples the cosine of the scattering angle.
  double sample_cos_theta(double u) const;
  // New direction after scattering from unit direction 'dir' (two uniforms).
  Vec3 sample_direction(const Vec3& dir, double u1, double u2) const;
  // p(cos theta), normalized over the sphere.
  double eval(double cos_theta) const;
  // Mean cosine: exact for HG, exact integral of the piecewise-linear table otherwise.
  double mean_cosine() const;
  bool is_henyey_greenstein() const { return mu_.empty(); }

 private:
  double g_ = 0;                      // HG parameter
  std::vector<double> mu_, p_, cdf_;  // tabulated: nodes, density in mu (integrates to 1), cdf
};

}  // namespace weft
