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
// * Colours are linear RGB (weft::Rgb). Spectral tables are reduced to RGB when loaded; a
//   spectral render reads their bands instead (bsdfs.h eval_bands).
//
// Every material is a small value type with eval, sample and pdf as below (the BsdfModel concept);
// the closed set a scene can name is weft::Bsdf in bsdfs.h.
#include <concepts>
#include <optional>

#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft {

struct BsdfSample {
  Vec3 wi;
  Rgb weight;      // f * |cos theta_i| / pdf
  double pdf = 0;  // solid-angle density of wi
  bool is_delta = false;
};

template <class B>
concept BsdfModel = requires(const B& b, const Vec3& w, Vec2 u, double u_lobe) {
  { b.eval(w, w) } -> std::same_as<Rgb>;
  { b.sample(w, u, u_lobe) } -> std::same_as<std::optional<BsdfSample>>;
  { b.pdf(w, w) } -> std::same_as<double>;
};

// Cosine-weighted direction on the upper (z > 0) hemisphere (Malley's method).
Vec3 sample_cosine_hemisphere(Vec2 u);

}  // namespace weft
