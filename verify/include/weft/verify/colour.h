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
  Rgb linear_srgb;                   // D65, unclipped (negative = out of gamut)
  Hsv hsv;                           // of the linear sRGB with negative components set to 0
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
