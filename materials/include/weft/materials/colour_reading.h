#pragma once
// What a d/8 spectrophotometer with the specular component included reads of a material: its
// directional-hemispherical reflectance for light near the normal (by reciprocity the same as
// diffuse light read at 8 degrees), and the colour targets that name a material, beside core's
// (core/colour_target.h):
//   measured:NAME   a bundled measured fabric (materials/data/measured/NAME), its neural fit
//                   integrated at 8 degrees; in the measurement's RGB, taken as linear sRGB (MERL's
//                   camera RGB is close to it but not it: docs/colour.md says what that costs)
//   table:FILE.exr  a BSDF table's reflectance in the incident bin of the normal, spectral or RGB
#include <string>

#include "weft/core/colour_target.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/measured_nbrdf.h"

namespace weft {

// The d/8 geometry's angle of incidence.
inline constexpr double kD8IncidenceDeg = 8;

// The measured BRDF's directional-hemispherical reflectance at kD8IncidenceDeg: a midpoint rule
// over cells_per_side^2 cells of equal cosine-weighted solid angle (sin^2 theta, phi).
Rgb nbrdf_d8_reflectance(const NbrdfNetwork& network, int cells_per_side = 96);

// A table's reflectance in the incident bin of the normal, per channel.
std::vector<double> table_d8_reflectance(const TabulatedBsdfTable& table);

// Any colour spec: core's forms, measured:NAME and table:FILE.exr; weft::Error naming 'field'.
ColourTarget read_colour_target(const std::string& spec, const std::string& field);

}  // namespace weft
