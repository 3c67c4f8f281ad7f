#include "weft/verify/settings.h"

#include "weft/core/error.h"

namespace weft {

VerifyQuality parse_verify_quality(const std::string& name) {
  if (name == "draft") return VerifyQuality::kDraft;
  if (name == "default") return VerifyQuality::kDefault;
  if (name == "publication") return VerifyQuality::kPublication;
  throw Error("", "--quality", "'" + name + "' is not draft, default or publication");
}

std::string quality_name(VerifyQuality q) {
  return q == VerifyQuality::kDraft     ? "draft"
         : q == VerifyQuality::kDefault ? "default"
                                        : "publication";
}

VerifySettings verify_settings(VerifyQuality q) {
  VerifySettings s;
  s.quality = q;
  switch (q) {
    case VerifyQuality::kDraft:
      s.resolution = 6;
      s.fiber_photons_per_band = 20000;
      s.particles_per_bin = 4000;
      s.batches = 2;
      s.summation_samples = 4;
      s.render_size = 64;
      s.render_spp = 2;
      s.weave_render_size = 128;
      s.weave_render_spp = 4;
      break;
    case VerifyQuality::kDefault:
      s.resolution = 8;
      s.fiber_photons_per_band = 200000;  // FiberTableBakeOptions{}'s
      s.particles_per_bin = 64000;
      s.batches = 4;
      s.summation_samples = 8;
      s.render_size = 128;
      s.render_spp = 4;
      s.weave_render_size = 256;
      s.weave_render_spp = 16;
      break;
    case VerifyQuality::kPublication:
      s.resolution = 12;
      s.fiber_photons_per_band = 1000000;
      s.particles_per_bin = 256000;
      s.batches = 8;
      s.summation_samples = 16;
      s.render_size = 384;
      s.render_spp = 64;
      s.weave_render_size = 512;
      s.weave_render_spp = 32;
      break;
  }
  return s;
}

}  // namespace weft
