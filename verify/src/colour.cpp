#include "weft/verify/colour.h"

#include "weft/core/error.h"

namespace weft {

ColourEntry colour_of_spectrum(const std::string& name, const Spectrum& s,
                               const std::string& note) {
  ColourEntry e;
  e.name = name;
  e.spectrum = s;
  e.note = note;
  e.rgb = xyz_to_linear_srgb(reflectance_to_xyz_d65(s));
  // The RGB stays as it is; HSV has no meaning outside the gamut, so the H, S, V shown are of
  // the colour with its negative components at 0, and the note says so.
  Rgb shown = e.rgb;
  GamutClip outside;
  outside.clip(shown);
  e.hsv = rgb_to_hsv(shown);
  if (outside.components)
    e.note += (e.note.empty() ? "" : "; ") +
              std::string(
                  "outside the sRGB gamut (RGB kept unclamped); H, S, V of it with its "
                  "negative components at 0, for display");
  return e;
}

FabricSpectra normal_incidence_spectra(const TabulatedBsdfTable& t) {
  if (t.channels != kNumBands)
    throw Error("", "channels", "the colour table needs a spectral (33-band) fabric table");
  const auto a = t.directional_albedo(t.grid().bin_of({0, 0, 1}));
  FabricSpectra s;
  for (int b = 0; b < kNumBands; ++b) {
    s.reflectance[b] = a.reflectance[b];
    s.transmittance[b] = a.transmittance[b];
  }
  return s;
}

}  // namespace weft
