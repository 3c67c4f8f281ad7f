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
  // The default's photons are FiberTableBakeOptions{}'s; what a row omits keeps its default.
  static const VerifySettings kDraft{.quality = VerifyQuality::kDraft,
                                     .resolution = 6,
                                     .fiber_photons_per_band = 5000,
                                     .particles_per_bin = 4000,
                                     .batches = 2,
                                     .summation_samples = 4,
                                     .render_size = 64,
                                     .render_spp = 2,
                                     .weave_render_size = 128,
                                     .weave_render_spp = 4};
  static const VerifySettings kDefault{.quality = VerifyQuality::kDefault,
                                       .resolution = 8,
                                       .fiber_photons_per_band = 50000,
                                       .particles_per_bin = 16000,
                                       .batches = 4,
                                       .summation_samples = 8,
                                       .render_size = 128,
                                       .render_spp = 4,
                                       .weave_render_size = 256,
                                       .weave_render_spp = 8};
  static const VerifySettings kPublication{.quality = VerifyQuality::kPublication,
                                           .resolution = 12,
                                           .fiber_photons_per_band = 250000,
                                           .particles_per_bin = 256000,
                                           .batches = 8,
                                           .summation_samples = 16,
                                           .render_size = 384,
                                           .render_spp = 64,
                                           .weave_render_size = 512,
                                           .weave_render_spp = 32};
  return q == VerifyQuality::kDraft     ? kDraft
         : q == VerifyQuality::kDefault ? kDefault
                                        : kPublication;
}

}  // namespace weft
