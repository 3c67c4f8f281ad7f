#pragma once
// The fabric's colour in reflection and transmission (the paper's Table 1).
#include <optional>
#include <string>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct ColourEntry {
  std::string name;
  std::optional<Spectrum> spectrum;  // absent for entries given as RGB or HSV
  // In 'colour_space': linear sRGB (D65, unclipped: negative = out of gamut) for Weft's own; a
  // measurement's in its own RGB space.
  Rgb rgb;
  std::string colour_space = "linear sRGB";
  Hsv hsv;  // of the RGB with negative components set to 0 (for display; the note says so)
  // Whether its absolute colour compares with the models' linear sRGB (a measurement in camera
  // RGB or an unknown space does not).
  bool comparable = true;
  std::string note;
};

// The colour of a reflectance or transmittance spectrum under D65 through CIE 1931.
ColourEntry colour_of_spectrum(const std::string& name, const Spectrum& spectrum,
                               const std::string& note);

// Reflectance and transmittance spectra of a spectral fabric table (33 bands) at normal
// incidence (the directional albedo of the wi bin containing the normal, materials/bsdf_table.h).
struct FabricSpectra {
  Spectrum reflectance{}, transmittance{};
};
FabricSpectra normal_incidence_spectra(const TabulatedBsdfTable& spectral_table);

}  // namespace weft
