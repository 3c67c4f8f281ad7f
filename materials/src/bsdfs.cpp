#include "weft/materials/bsdfs.h"

#include <cmath>
#include <type_traits>

namespace weft {
namespace {

// The material's table when it is read per band (a spectral table), else null: a grey material.
const TabulatedBsdf* band_table(const Bsdf& bsdf) {
  const auto* t = std::get_if<TabulatedBsdf>(&bsdf.variant());
  return t && t->data && !t->data->bands.empty() ? t : nullptr;
}

}  // namespace

std::string spectral_obstacle(const Bsdf& bsdf) {
  return std::visit(
      [&](const auto& b) -> std::string {
        using T = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<T, LambertBsdf>) {
          if (!b.reflectance.is_grey())
            return "a coloured lambert reflectance is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, CookTorranceBsdf>) {
          if (!b.tint.is_grey())
            return "a coloured cook_torrance tint is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, ClassicFiberBsdf>) {
          if (!b.reflectance.is_grey() || !b.surface.tint.is_grey())
            return "a coloured classic_fiber reflectance is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, TabulatedBsdf>) {
          if (!b.data || b.data->bands.empty())
            return "an RGB table has no spectral values (bake a spectral one)";
          if (!b.scale.is_grey())
            return "a coloured tint on a spectral table is RGB, not a spectrum (give it grey)";
          if (b.backing) return "a table on a backing is rendered in RGB only";
        } else {
          return "a measured BRDF is RGB only";
        }
        return "";
      },
      bsdf.variant());
}

void eval_bands(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi, Spectrum& out) {
  if (const TabulatedBsdf* t = band_table(bsdf)) return t->eval_bands(wo, wi, out);
  out.fill(bsdf.eval(wo, wi).r);
}

void sample_weight_bands(const Bsdf& bsdf, const Vec3& wo, const BsdfSample& s, Spectrum& out) {
  const TabulatedBsdf* t = band_table(bsdf);
  if (!t) return out.fill(s.weight.r);
  t->eval_bands(wo, s.wi, out);
  const double k = s.pdf > 0 ? std::abs(s.wi.z) / s.pdf : 0.0;
  for (double& v : out) v *= k;
}

}  // namespace weft
