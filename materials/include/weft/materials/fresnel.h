#pragma once
// Fresnel equations for a smooth dielectric boundary (unpolarized light).
#include <cmath>

#include "weft/core/math.h"
#include "weft/core/vec.h"

namespace weft {

// Reflectance for light arriving with cosine cos_i (> 0) from the side of index n_i into index
// n_t. Returns 1 for total internal reflection. cos_t_out receives the transmitted cosine (> 0).
inline double fresnel_dielectric(double cos_i, double n_i, double n_t,
                                 double* cos_t_out = nullptr) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double eta = n_i / n_t;
  const double sin2_t = eta * eta * (1 - cos_i * cos_i);
  if (sin2_t >= 1) {
    if (cos_t_out) *cos_t_out = 0;
    return 1;
  }
  const double cos_t = std::sqrt(1 - sin2_t);
  if (cos_t_out) *cos_t_out = cos_t;
  const double rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
  const double rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// Refracts direction d (travelling, unit) through a boundary with unit normal n facing the
// incident side (dot(d, n) < 0), from index n_i to n_t. Returns false on total internal reflection.
inline bool refract(const Vec3& d, const Vec3& n, double n_i, double n_t, Vec3* out) {
  const double eta = n_i / n_t;
  const double cos_i = -dot(d, n);
  const double sin2_t = eta * eta * (1 - cos_i * cos_i);
  if (sin2_t >= 1) return false;
  const double cos_t = std::sqrt(1 - sin2_t);
  *out = eta * d + (eta * cos_i - cos_t) * n;
  return true;
}

}  // namespace weft
