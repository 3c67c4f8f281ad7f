#pragma once
// A colour a user knows, as a target (`--colour SPEC`, weft.bake_fabric(colour=...)): what a d/8
// spectrophotometer with the specular component included (SCI) would read of the fabric, its
// hemispherical reflectance for light near the normal. SPEC is one of
//   srgb:#RRGGBB      an sRGB colour (IEC 61966-2-1, D65), e.g. from a colour standard's swatch
//   lab:L,a,b         CIELAB, D65, CIE 1931 2-degree observer
//   lab10:L,a,b       CIELAB, D65, CIE 1964 10-degree observer (the textile trade's usual one)
//   spectrum:FILE.csv a reflectance spectrum: rows of wavelength (nm), reflectance (0-1), as a
//                     spectrophotometer exports them; a header line and '#' comments are skipped
// and the forms that name a material (materials/colour_reading.h): measured:NAME, table:FILE.exr.
#include <optional>
#include <string>

#include "weft/core/colorimetry.h"

namespace weft {

struct ColourTarget {
  std::string spec;  // as given
  enum class Kind { kSrgb, kLab, kSpectrum } kind = Kind::kLab;
  Observer observer = Observer::kCie1931TwoDegree;  // the one its Lab is for
  Lab lab;                                          // the target colour
  std::optional<Spectrum> reflectance;              // a spectrum target's, per band
  std::string file;                                 // a spectrum target's file
  // Identifies the target in cache keys: the spec, its Lab, and a spectrum's values.
  std::string key() const;
  // The colour of a reflectance spectrum as this target states colour (its observer; sRGB targets
  // are compared under the 2-degree observer, for which sRGB is defined).
  Lab lab_of(const Spectrum& reflectance) const;
};

// A spectrum file's bounds: a spectrophotometer reads 31 to 81 wavelengths (400-700 nm at 10 nm,
// 360-760 nm at 5 nm); 1 nm exports of 380-780 nm have 401 rows. 100 000 rows or 4 MiB refuse
// absurd files before reading them.
inline constexpr size_t kMaxSpectrumRows = 100000, kMaxSpectrumFileBytes = 4u << 20;
// The range it must cover: the visible bands carrying nearly all of D65 times the observer.
inline constexpr double kSpectrumMinStartNm = 400, kSpectrumMinEndNm = 700;
// Reflectances above this are a percentage given as a fraction (fluorescent whites reach ~1.1).
inline constexpr double kMaxSpectrumReflectance = 1.5;

// A linear sRGB reading (e.g. a table's or a measurement's d/8 reflectance) as a target compared
// like srgb: targets; 'spec' names where it came from.
ColourTarget linear_srgb_target(const Rgb& linear, const std::string& spec);

// Parses SPEC; weft::Error naming 'field' (and the file of a spectrum) and saying what is allowed.
ColourTarget parse_colour_target(const std::string& spec, const std::string& field);

// A reflectance spectrum from a file of (wavelength nm, reflectance) rows, averaged over each band
// (linear between the rows; the ends held flat past the data for at most 15 nm).
Spectrum read_reflectance_csv(const std::string& file, const std::string& field);

}  // namespace weft
