#pragma once
// Lights, and the one interface the path tracer uses for all of them (after pbrt-v4's Light:
// SampleLi, PDF_Li and L/Le, here sample, pdf and eval). The kinds: parallel (directional), point
// and spot, a constant environment, environment maps (environment_map.h: an OpenEXR file or the
// CIE clear sky), and the emissive triangles of the geometry as one area light.
// The closed set is weft::Light, a std::variant as for BSDFs (materials/bsdfs.h).
//
// Conventions, stated once for every light:
// * Directions are unit world-space vectors; sample(p, rng) returns wi pointing FROM the shading
//   point p TOWARDS the light.
// * What arrives at p along wi is L * falloff / pdf. The three stay apart because the path tracer
//   forms every estimate as f * L * (|cos| * mis * falloff / pdf) in this one order:
//   - area and environment lights: L is radiance (W m^-2 sr^-1), falloff is 1 and pdf is the
//     solid-angle density with which wi was drawn;
//   - delta lights (is_delta(): parallel, point, spot), which nothing but sample() can find:
//     L * falloff / pdf is the irradiance on a plane facing the light (W m^-2). Parallel: L is that
//     irradiance and pdf is 1. Point and spot: L is the radiant intensity (W sr^-1), pdf is the
//     squared distance (the inverse-square law) and falloff the spot's cone factor.
// * A sample's shadow ray ends just short of p_light, or runs to infinity along wi (at_infinity).
// * eval(hit) and pdf(hit) serve rays that find a light by BSDF sampling (LightHit): the radiance
//   the ray meets there (emitted back towards its origin) and the solid-angle density with which
//   sample() would have drawn the ray's direction from its origin. Both are 0 for delta lights and
//   where the ray did not meet this light.
// * sample() draws the random numbers it needs from rng, always as many and in the same order:
//   none for delta lights, two for the environment, three for the area light (a triangle, then a
//   point on it). It returns nullopt when nothing can arrive (p outside a spot's cone, at a point
//   light, or an emitter seen edge-on or from its unlit back).
// * Colours are linear RGB (weft::Rgb), per channel.
#include <concepts>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"
#include "weft/scenes/environment_map.h"
#include "weft/scenes/mesh.h"

namespace weft {

struct LightSample {
  Vec3 wi;  // unit, from the shading point towards the light
  Rgb L;    // radiance; for delta lights irradiance (parallel) or intensity (point, spot)
  double falloff = 1;  // a spot's cone factor in (0, 1]; 1 for every other light
  double pdf = 1;      // solid-angle density of wi; for delta lights the divisor described above
  Vec3 p_light;        // where the shadow ray ends, unless at_infinity
  bool at_infinity = false;
};

// Where a ray that left a shading point along 'dir' (unit) ended: on a surface (triangle 'prim' of
// mesh 'mesh', unit geometric normal 'ng', at 'distance' from the ray's origin), or nowhere: it
// left the scene ('escaped').
struct LightHit {
  Vec3 dir;
  bool escaped = true;
  uint32_t mesh = 0, prim = 0;
  Vec3 ng;
  double distance = 0;

  static LightHit escaped_along(const Vec3& dir) { return {dir, true, 0, 0, {}, 0}; }
  static LightHit on_surface(const Vec3& dir, uint32_t mesh, uint32_t prim, const Vec3& ng,
                             double distance) {
    return {dir, false, mesh, prim, ng, distance};
  }
};

// A parallel beam: irradiance on a surface facing it, arriving from 'to_light'.
struct DirectionalLight {
  Vec3 to_light{0, 1, 0};  // unit, from the scene towards the light
  Rgb irradiance{1.0};     // W/m^2 per channel, on a plane perpendicular to the beam

  bool is_delta() const { return true; }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const;
  double pdf(const LightHit&) const { return 0; }
  Rgb eval(const LightHit&) const { return Rgb(0.0); }
};

// Point light of radiant intensity 'intensity' (W/sr); a spot when cos_outer > -1, with the
// smooth angular falloff of KHR_lights_punctual between the inner and outer cone.
struct PointLight {
  Vec3 position{0, 0, 0};
  Rgb intensity{1.0};
  Vec3 spot_direction{0, 0, -1};  // unit, the direction the spot shines to
  double cos_inner = -1, cos_outer = -1;

  bool is_spot() const { return cos_outer > -1; }
  double falloff(const Vec3& from_light) const;  // 1 for a point light

  bool is_delta() const { return true; }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const;
  double pdf(const LightHit&) const { return 0; }
  Rgb eval(const LightHit&) const { return Rgb(0.0); }
};

// Constant radiance arriving from every direction; sampled uniformly over the sphere.
struct EnvironmentLight {
  Rgb radiance{0.0};

  bool is_delta() const { return false; }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const;
  double pdf(const LightHit& hit) const;
  Rgb eval(const LightHit& hit) const;
};

// Every emissive triangle of a scene as one light: sample() picks a triangle with probability
// proportional to its power (area x mean radiance, twice for two-sided emitters) and a point
// uniformly on it. Copies share the (immutable) triangle data.
class AreaLight {
 public:
  // What a mesh emits: radiance on its front side (counter-clockwise winding), or both sides.
  struct Emission {
    Rgb radiance{0.0};  // black: the mesh does not emit
    bool two_sided = false;
  };

  AreaLight() = default;
  // One emission per mesh; mesh indices are those of LightHit::mesh.
  AreaLight(std::vector<std::shared_ptr<const TriangleMesh>> meshes,
            const std::vector<Emission>& emission);

  bool empty() const;               // no emissive triangle
  bool emits(uint32_t mesh) const;  // the mesh's emission is not black

  bool is_delta() const { return false; }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const;
  double pdf(const LightHit& hit) const;
  Rgb eval(const LightHit& hit) const;

 private:
  struct Data;
  std::shared_ptr<const Data> data_;
};

template <class T>
concept LightModel = requires(const T& l, const Vec3& p, Rng& rng, const LightHit& hit) {
  { l.is_delta() } -> std::same_as<bool>;
  { l.sample(p, rng) } -> std::same_as<std::optional<LightSample>>;
  { l.pdf(hit) } -> std::same_as<double>;
  { l.eval(hit) } -> std::same_as<Rgb>;
};

using LightVariant =
    std::variant<DirectionalLight, PointLight, EnvironmentLight, AreaLight, EnvironmentMap>;

class Light {
 public:
  template <LightModel T>
  requires(!std::same_as<T, Light>) Light(T value)
      : impl_(std::move(value)) {}  // NOLINT: implicit from any member of the set

  bool is_delta() const {
    return std::visit([](const auto& l) { return l.is_delta(); }, impl_);
  }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const {
    return std::visit([&](const auto& l) { return l.sample(p, rng); }, impl_);
  }
  double pdf(const LightHit& hit) const {
    return std::visit([&](const auto& l) { return l.pdf(hit); }, impl_);
  }
  Rgb eval(const LightHit& hit) const {
    return std::visit([&](const auto& l) { return l.eval(hit); }, impl_);
  }
  const LightVariant& variant() const { return impl_; }

 private:
  LightVariant impl_;
};

// The lights a scene description gives (its "lights" and glTF KHR_lights_punctual), by kind.
// Emissive surfaces are not here: they are geometry (render_scene.h makes their AreaLight).
struct Lights {
  std::vector<DirectionalLight> directional;
  std::vector<PointLight> points;
  Rgb environment{0.0};  // constant radiance arriving from every direction (environments add up)
  std::vector<EnvironmentMap> environment_maps;  // environment_map.h, each its own light
};

// One line per light for a render log: its kind, where it is, and its radiometric value with the
// unit (W/m^2 irradiance, W/sr intensity, W m^-2 sr^-1 radiance).
std::vector<std::string> describe_lights(const Lights& lights);

}  // namespace weft
