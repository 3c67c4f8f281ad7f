#pragma once
// The closed set of BSDFs a scene can name (the interface and its conventions are in bsdf.h).
// Dispatch is a std::variant: adding a material adds its alternative here and its factory in
// registry.cpp. fiber_table and fabric_table are both TabulatedBsdf (the table's kind tells them
// apart).
#include <string>
#include <variant>

#include "weft/materials/bsdf.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/lambert.h"
#include "weft/materials/measured_nbrdf.h"
#include "weft/materials/tabulated_bsdf.h"

namespace weft {

using BsdfVariant =
    std::variant<LambertBsdf, CookTorranceBsdf, ClassicFiberBsdf, TabulatedBsdf, MeasuredNbrdfBsdf>;

class Bsdf {
 public:
  Bsdf() = default;
  template <BsdfModel T>
  requires(!std::same_as<T, Bsdf>) Bsdf(T value)
      : impl_(std::move(value)) {}  // NOLINT: implicit from any member of the set

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

// What a spectral render (render_settings.h RenderSettings::spectral) needs of a material: f per
// band. A spectral table has it (without a backing, with a grey tint); a material whose colour is
// grey (equal components) is the same at every band. spectral_obstacle is "" for those, else
// what is missing (an RGB colour or table, a measured RGB BRDF, a table on a backing).
std::string spectral_obstacle(const Bsdf& bsdf);
// f(wo, wi) per band, for a material without a spectral obstacle.
void eval_bands(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi, Spectrum& out);
// The weight of a sample of bsdf.sample(wo, ...) per band: f |cos theta_i| / pdf (for a grey
// material the sample's own weight, delta lobes included).
void sample_weight_bands(const Bsdf& bsdf, const Vec3& wo, const BsdfSample& sample, Spectrum& out);

}  // namespace weft
