#pragma once
// An equirectangular (latitude-longitude) environment map as a light, following lights.h's
// conventions (sample, pdf, eval; L is radiance, pdf the solid-angle density). Texel (column i,
// row j) of a W x H map covers zenith angles [j, j+1] pi / H from the frame's normal (row 0 is
// the zenith) and azimuths [i, i+1] 2 pi / W from the frame's tangent, turning towards
// normal x tangent: the zenith/azimuth convention of the scene description (AngleFrame), so a
// sun at (zenith_deg, azimuth_deg) and the map's bright spot at the same angles agree. Radiance
// is constant over a texel; sampling picks texels in proportion to their mean RGB times their
// solid angle (piecewise constant, pbrt-v3's InfiniteAreaLight with sin(theta) folded in), so an
// estimate L / pdf is nearly constant over a map.
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "weft/core/distribution.h"
#include "weft/core/frame.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

namespace weft {

struct LightHit;
struct LightSample;

// A map in memory: width x height texels of linear RGB, row 0 at the zenith.
struct EnvironmentTexels {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 floats per texel, row-major
};

// Reads the R, G, B channels of an OpenEXR file (any pixel type, the data window). Error naming
// the file: missing, not OpenEXR, without R/G/B, negative or non-finite values, over
// kMaxEnvironmentTexels texels.
inline constexpr size_t kMaxEnvironmentTexels = size_t(1) << 26;
EnvironmentTexels read_environment_exr(const std::filesystem::path& path);

// The CIE standard clear sky (CIE S 011 / ISO 15469, sky type 12; the "CIE clear" sky of
// Radiance's gensky): luminance relative to the zenith's, for a sky point at zenith angle
// 'zenith' and angle 'gamma' from the sun, the sun at zenith angle 'sun_zenith' (radians):
//   L / L_z = f(gamma) phi(zenith) / (f(sun_zenith) phi(0)),
//   phi(Z) = 1 - exp(-0.32 / cos Z),  f(x) = 1 + 10 (exp(-3 x) - exp(-3 pi / 2)) + 0.45 cos^2 x.
// 0 below the horizon (the ground is geometry).
double cie_clear_sky_relative(double zenith, double gamma, double sun_zenith);

// That sky as a width x height map (row 0 at the zenith, as EnvironmentMap reads it), each texel
// the mean over 4 x 4 points spread evenly in solid angle, times 'zenith_radiance' (the model
// gives luminance only: the colour is the same everywhere). The sun's zenith and azimuth are in
// the map's angles (radians); the sun's disc itself is not in the map (a parallel light is).
EnvironmentTexels cie_clear_sky_texels(const Rgb& zenith_radiance, double sun_zenith,
                                       double sun_azimuth, int width, int height);

class EnvironmentMap {
 public:
  EnvironmentMap() = default;
  // 'frame': zenith (n) and azimuth reference (s); 'scale' multiplies every texel. Error (naming
  // 'source') when the map is empty or black.
  EnvironmentMap(EnvironmentTexels texels, const Frame& frame, const Rgb& scale,
                 const std::string& source = "");

  bool is_delta() const { return false; }
  std::optional<LightSample> sample(const Vec3& p, Rng& rng) const;
  double pdf(const LightHit& hit) const;
  Rgb eval(const LightHit& hit) const;

  // The radiance arriving from direction 'dir' (unit, towards the environment), and the density
  // sample() draws it with.
  Rgb radiance(const Vec3& dir) const;
  double pdf_dir(const Vec3& dir) const;
  // Integral of the radiance over the sphere (W m^-2 per channel... radiance times sr), exact for
  // the piecewise-constant map; for tests.
  Rgb integral() const;
  // Whether every texel times the scale has equal R, G and B (one colour at every wavelength, as
  // a spectral render needs: a CIE sky of a grey zenith radiance is).
  bool is_grey() const;

 private:
  struct Data {
    EnvironmentTexels texels;
    Frame frame;
    Rgb scale;
    Distribution2D dist;
  };
  std::shared_ptr<const Data> data_;
  Vec2 uv_of(const Vec3& dir) const;
};

}  // namespace weft
