#pragma once
// Measured fabric BRDFs from MERL (Matusik et al. 2003) and RGL (Dupuy & Jakob 2018) through
// their neural fits (Sztrajman, Rainer, Ritschel, Weyrich, "Neural BRDF Representation and
// Importance Sampling", CGF 2021): a 6-21-21-3 MLP
//   f_r = max(exp(W3^T relu(W2^T relu(W1^T x + b1) + b2) + b3) - 1, 0)   [1/sr, per RGB channel]
// with x = (sin theta_h, 0, cos theta_h, d_x, d_y, d_z): Rusinkiewicz half/difference coordinates,
// h = normalize(wi + wo), d = R_y(-theta_h) R_z(-phi_h) wi, wi towards the light.
// Colours are MERL's camera RGB (merl-*) or linear sRGB (rgl-*), as each folder's inplane.csv
// states (materials/data/measured/README.md).
// The measurement is reflection only: f = 0 when wo and wi lie on opposite sides; for wo.z < 0
// both directions are mirrored (the back side is the same material), like the other reflectors.
// Sampling is cosine-weighted on wo's side.
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/materials/bsdf.h"

namespace weft {

struct NbrdfNetwork {
  static constexpr int kIn = 6, kHidden = 21, kOut = 3;
  std::array<double, kIn * kHidden> w1{};  // (in, out) row-major
  std::array<double, kHidden> b1{};
  std::array<double, kHidden * kHidden> w2{};
  std::array<double, kHidden> b2{};
  std::array<double, kHidden * kOut> w3{};
  std::array<double, kOut> b3{};

  // Parses nbrdf_weights.txt ('#' comments, then blocks "NAME rows cols" or "NAME n" followed by
  // the numbers, in the order W1 b1 W2 b2 W3 b3). Throws weft::Error naming file and block.
  static NbrdfNetwork load(const std::filesystem::path& path);

  // f_r for wo.z > 0 and wi.z > 0 (callers handle the other cases).
  Rgb eval_upper(const Vec3& wo, const Vec3& wi) const;
};

// Bundled measured materials: the folders of materials/data/measured ("merl-red-fabric", ...).
std::vector<std::string> measured_nbrdf_names();
// The weights file of a bundled material (materials/data/measured/<name>, found by
// find_bundled_file: the install, then the source tree). Throws weft::Error listing the places
// tried.
std::filesystem::path find_measured_nbrdf(const std::string& name);

struct MeasuredNbrdfBsdf {
  std::shared_ptr<const NbrdfNetwork> network;

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
};

}  // namespace weft
