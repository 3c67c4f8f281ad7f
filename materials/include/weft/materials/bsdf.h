#pragma once
// The BSDF interface of Weft. Conventions, stated once for every material:
//
// * Directions are unit vectors in the local shading frame: z is the shading normal n, x the
//   tangent t (for fibers and fabrics: the fiber / yarn axis, carried by glTF tangents), y the
//   binormal b = n x t. Both directions point AWAY from the surface.
// * wo is the given direction (towards the camera / the previous path vertex); wi is the one that
//   is sampled (towards the light / the next vertex). Light travels wi -> surface -> wo.
// * eval(wo, wi) returns f(wo, wi) in 1/sr WITHOUT the cosine factor. It is defined on the whole
//   sphere for both arguments: wo.z * wi.z < 0 is transmission, and wo.z < 0 is the back side.
//   Materials that reflect on one side only return 0 where they do not apply.
// * sample(wo, u, u_lobe) draws wi with density pdf(wo, wi) (solid angle) and returns
//   weight = f(wo, wi) * |cos theta_i| / pdf. It returns nullopt when no direction can be drawn.
// * pdf(wo, wi) is the solid-angle density of sample; it agrees with sample to rounding.
// * Colours are linear RGB (weft::Rgb). Spectral tables are reduced to RGB when loaded.
#include <optional>
#include <variant>

#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"
#include "weft/materials/bsdf_sample.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/lambert.h"
#include "weft/materials/measured_nbrdf.h"
#include "weft/materials/tabulated_bsdf.h"

namespace weft {

// The closed set of BSDFs; other materials add their alternative here.
// fiber_table and fabric_table are both TabulatedBsdf (the table's kind tells them apart).
using BsdfVariant =
    std::variant<LambertBsdf, CookTorranceBsdf, ClassicFiberBsdf, TabulatedBsdf, MeasuredNbrdfBsdf>;

class Bsdf {
 public:
  Bsdf() = default;
  template <class T>
  Bsdf(T value) : impl_(std::move(value)) {}  // NOLINT: implicit from any member of the set

  Rgb eval(const Vec3& wo, const Vec3& wi) const {
    return std::visit([&](const auto& b) { return b.eval(wo, wi); }, impl_);
  }
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const {
    return std::visit([&](const auto& b) { return b.sample(wo, u, u_lobe); }, impl_);
  }
  double pdf(const Vec3& wo, const Vec3& wi) const {
    return std::visit([&](const auto& b) { return b.pdf(wo, wi); }, impl_);
  }
  const BsdfVariant& variant() const { return impl_; }

 private:
  BsdfVariant impl_;
};

}  // namespace weft
