#pragma once
// A table's radiance coefficient in the plane of incidence, beta = pi f, where the measurement has
// it.
//
// Why the tables and not the gonioreflectometer sweep: a fabric table is the cloth's BSDF, the
// quantity a gonioreflectometer on an infinite sample measures, so beta at any (incidence, view)
// is pi times the table's value; one table serves every incidence, where the sweep renders one
// image per view and incidence (9 x 35 renders for the bundled measurement) and adds the edges of
// a finite patch. The table's resolution limits the angular detail (a bin spans about
// 180 / (2 R) degrees), which the quality levels trade against time.
//
// In-plane directions (cloth frame, z = normal): light at zenith theta_i and azimuth phi,
// w_i = (sin theta_i cos phi, sin theta_i sin phi, cos theta_i); a view zenith v > 0 lies on the
// mirror side (the paper's Fig. 7), w_o = (-sin v cos phi, -sin v sin phi, cos v). The measured
// tables are of isotropic fits, so the computed values are averaged over 'azimuths' planes
// phi = 360 k / azimuths.
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/verify/measured.h"

namespace weft {

// beta = pi f of an RGB table (3 channels), averaged over 'azimuths' planes of incidence, for
// each view of 'views_deg' (paper's sign).
std::vector<Rgb> inplane_beta(const TabulatedBsdfTable& rgb_table, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths);

// What a spectral table's reduction to linear sRGB left outside the gamut: components below 0
// (a saturated colour), kept as they are.
struct OutOfGamut {
  size_t components = 0;
  double largest = 0;  // largest magnitude below 0
};

// A spectral table (33 bands) as linear sRGB under D65 (core/spectrum.h bands_to_linear_srgb),
// unclamped: negative components of colours outside the gamut are kept (the metrics take them
// as they are, figures.h kLogFloorFraction) and counted in 'out_of_gamut'. A 3-channel table is
// returned as it is.
TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& table,
                                OutOfGamut* out_of_gamut = nullptr);

// beta [incidence][view] of an RGB or spectral table at the measurement's views.
std::vector<std::vector<Rgb>> table_curves(const TabulatedBsdfTable& table,
                                           const MeasuredInplane& measured, int azimuths);

}  // namespace weft
