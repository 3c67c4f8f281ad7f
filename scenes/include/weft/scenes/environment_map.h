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
