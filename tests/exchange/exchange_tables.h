#pragma once
// Small analytic tables for the export tests, with known exact answers.
#include <algorithm>
#include <cmath>
#include <span>

#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft::testing {

// Lambertian reflection rho / pi on either side and Lambertian transmission tau / pi through the
// cloth, per channel ('rho' and 'tau' hold one value per channel). A constant per cell pair, so
// every cell average and every interpolation of it is exact (bsdf_table.h: from_function's ratio
// estimator reproduces a constant exactly).
inline TabulatedBsdfTable lambert_table(int resolution, std::vector<double> rho,
                                        std::vector<double> tau) {
  const int channels = static_cast<int>(rho.size());
  return TabulatedBsdfTable::from_function(
      resolution, channels,
      [=](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const bool same_side = (wo.z > 0) == (wi.z > 0);
        for (int c = 0; c < channels; ++c)
          v[static_cast<size_t>(c)] = (same_side ? rho : tau)[static_cast<size_t>(c)] / kPi;
      },
      1, 1);
}

inline TabulatedBsdfTable lambert_rgb(int resolution = 8) {
  return lambert_table(resolution, {0.2, 0.5, 0.8}, {0, 0, 0});
}

// 33 bands, rho rising linearly from 0.1 at 390 nm to 0.9 at 710 nm.
inline std::vector<double> ramp_spectrum() {
  std::vector<double> rho;
  for (int b = 0; b < kNumBands; ++b) rho.push_back(0.1 + 0.8 * b / (kNumBands - 1.0));
  return rho;
}

// Lambertian rho / pi plus an isotropic, reciprocal sheen-like lobe towards grazing half vectors,
// on the upper side only: a table whose NDF estimate is not trivial.
inline TabulatedBsdfTable lobe_rgb(int resolution = 8) {
  return TabulatedBsdfTable::from_function(
      resolution, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        if (wo.z <= 0 || wi.z <= 0) {
          v[0] = v[1] = v[2] = 0;
          return;
        }
        const Vec3 h = normalize(wo + wi);
        const double lobe = 0.3 * (1 - h.z * h.z);
        v[0] = 0.6 / kPi + lobe, v[1] = 0.2 / kPi + lobe, v[2] = 0.1 / kPi + lobe;
      },
      2, 1);
}

// A cloth-like reflection on the upper side: a Lambertian base, a sheen towards grazing half
// vectors and a back-scatter lobe around the retro direction that grows towards grazing, as woven
// fabrics show (isotropic and reciprocal, so the export's isotropic average is the function).
inline void fabric_reflection(const Vec3& wo, const Vec3& wi, std::span<double> v) {
  const Vec3 h = normalize(wo + wi);
  const double sheen = 0.4 * (1 - h.z * h.z);
  const double back = 0.25 * std::pow(std::max(0.0, dot(wo, wi)), 8) / (wo.z + wi.z + 0.3);
  const double base[3] = {0.55, 0.3, 0.15};
  for (int c = 0; c < 3; ++c) v[static_cast<size_t>(c)] = base[c] / kPi + sheen + back;
}
// An RGB table of R = resolution that reflects as 'reflection' with light and view above the
// cloth, and sends nothing else.
template <class F>
TabulatedBsdfTable reflection_rgb(int resolution, F reflection) {
  return TabulatedBsdfTable::from_function(
      resolution, 3,
      [reflection](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        if (wo.z <= 0 || wi.z <= 0) {
          v[0] = v[1] = v[2] = 0;
          return;
        }
        reflection(wo, wi, v);
      },
      2, 1);
}
inline TabulatedBsdfTable fabric_rgb(int resolution = 8) {
  return reflection_rgb(resolution, fabric_reflection);
}

// A woven cloth made the way the paper's summation makes one (fabric_summation.h, kPaper: half a
// fiber along the warp, x, and half along the weft, y, each seen on its top), from a fiber with
// the lobes of a dyed fiber table: a white specular cone around the mirror of the light's angle
// to the fiber axis (sin theta_o = -sin theta_i, 4 deg wide), a red forward lobe on that cone
// (light through the fiber, towards the far side) and a dim diffuse term. What makes a baked
// fabric table hard to export and the Lambertian and fabric_rgb tables easy: it is anisotropic
// (the two fiber axes; the export averages rotations), its light at grazing views is a narrow
// forward lobe (a curved value between the export's sample points), and at R = 8 its cone is
// resolved only by the table's kinked interpolation between bins.
inline void woven_reflection(const Vec3& wo, const Vec3& wi, std::span<double> v) {
  constexpr double kWidth = 0.07, kDiffuse[3] = {0.02, 0.01, 0.015};
  for (int c = 0; c < 3; ++c) v[static_cast<size_t>(c)] = kDiffuse[c] / kPi;
  for (const Vec3 t : {Vec3{1, 0, 0}, Vec3{0, 1, 0}}) {
    const double si = dot(wi, t), so = dot(wo, t);
    const double cone =
        std::exp(-sqr(si + so) / (2 * sqr(kWidth))) / (kWidth * std::sqrt(2 * kPi) * 2 * kPi);
    const Vec3 pi = wi - si * t, po = wo - so * t;  // the directions across the fiber
    const double across = dot(pi, po) / std::sqrt(std::max(1e-12, dot(pi, pi) * dot(po, po)));
    const double forward =
        std::pow((1 - across) / 2, 4);  // 1 with light and view on opposite sides
    v[0] += 0.5 * cone * (0.04 + forward);
    v[1] += 0.5 * cone * (0.04 + 0.02 * forward);
    v[2] += 0.5 * cone * (0.04 + 0.03 * forward);
  }
}
inline TabulatedBsdfTable woven_rgb(int resolution = 8) {
  return reflection_rgb(resolution, woven_reflection);
}

}  // namespace weft::testing
