#include "weft/materials/bsdfs.h"

#include <type_traits>

namespace weft {
namespace {

bool grey(const Rgb& c) {
  return c.r == c.g && c.g == c.b;
}

}  // namespace

std::optional<Bsdf> band_group_bsdf(const Bsdf& bsdf, int group, std::string& why) {
  return std::visit(
      [&](const auto& b) -> std::optional<Bsdf> {
        using T = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<T, LambertBsdf>) {
          if (grey(b.reflectance)) return b;
          why = "a coloured lambert reflectance is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, CookTorranceBsdf>) {
          if (grey(b.tint)) return b;
          why = "a coloured cook_torrance tint is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, ClassicFiberBsdf>) {
          if (grey(b.reflectance) && grey(b.surface.tint)) return b;
          why = "a coloured classic_fiber reflectance is RGB, not a spectrum (give it grey)";
        } else if constexpr (std::is_same_v<T, TabulatedBsdf>) {
          if (!b.data || b.data->bands.empty()) {
            why = "an RGB table has no spectral values (bake a spectral one)";
          } else if (!grey(b.scale)) {
            why = "a coloured tint on a spectral table is RGB, not a spectrum (give it grey)";
          } else if (b.backing) {
            why = "a table on a backing is rendered in RGB only";
          } else {
            TabulatedBsdf g = b;
            g.band_group = group;
            return g;
          }
        } else {
          why = "a measured BRDF is RGB only";
        }
        return std::nullopt;
      },
      bsdf.variant());
}

}  // namespace weft
