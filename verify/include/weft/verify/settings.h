#pragma once
// What a verification's quality level sets: one place for the figures (docs/verify.md gives their
// times).
#include <cstdint>
#include <string>

namespace weft {

enum class VerifyQuality { kDraft, kDefault, kPublication };
VerifyQuality parse_verify_quality(const std::string& name);  // weft::Error naming "--quality"
std::string quality_name(VerifyQuality q);

struct VerifySettings {
  VerifyQuality quality = VerifyQuality::kDefault;
  int resolution = 8;                   // of the fiber and fabric tables
  uint64_t fiber_photons_per_band = 0;  // the fiber bake
  uint64_t particles_per_bin = 0;       // ray trace, all batches together
  int batches = 4;                      // independent ray traces (the error bars)
  int summation_samples = 8;            // direction pairs per cell pair (summation, classic)
  int azimuths = 24;                    // planes of incidence averaged
  int render_size = 96;                 // the renders of the sample (pixels per side)
  int render_spp = 4;                   // their samples per pixel
  int weave_render_size = 160;          // the fiber-level renders (pixels on the longer side)
  int weave_render_spp = 16;            // their samples per pixel
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores; results do not depend on it
};
VerifySettings verify_settings(VerifyQuality quality);

}  // namespace weft
