#pragma once
// A table's radiance coefficient in the plane of incidence, beta = pi f, and a table's reduction
// to linear sRGB. They are properties of the table alone, so they live beside it: verify compares
// them with a measurement (verify/inplane.h), and weft export draws them beside its preview
// (exchange/preview_html.h).
//
// In-plane directions (cloth frame, z = normal): light at zenith theta_i and azimuth phi,
// w_i = (sin theta_i cos phi, sin theta_i sin phi, cos theta_i); a view zenith v > 0 lies on the
// mirror side (the paper's Fig. 7), w_o = (-sin v cos phi, -sin v sin phi, cos v). The measured
// tables are of isotropic fits, so the computed values are averaged over 'azimuths' planes
// phi = 360 k / azimuths.
#include <cstddef>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/table_reader.h"

namespace weft {

// beta = pi f of an RGB table (3 channels) read with its sheen (table_reader.h), averaged over
// 'azimuths' planes of incidence, for each view of 'views_deg' (paper's sign).
std::vector<Rgb> inplane_beta(const TableReader& rgb_table, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths);

// What a spectral table's reduction to linear sRGB left outside the gamut: components below 0
// (a saturated colour), kept as they are.
struct OutOfGamut {
  size_t components = 0;
  double largest = 0;  // largest magnitude below 0
};

// A spectral table (33 bands) as linear sRGB under D65 (core/spectrum.h bands_to_linear_srgb),
// unclamped: negative components of colours outside the gamut are kept (verify's metrics take
// them as they are, figures.h kLogFloorFraction) and counted in 'out_of_gamut'. A 3-channel table
// is returned as it is.
TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& table,
                                OutOfGamut* out_of_gamut = nullptr);
// The same for a reader: its cells (the rest, with a sheen) and its sheen each reduced alike, so
// that the reduced reader's f is the reduction of the reader's (the reduction is linear). A
// 3-channel reader is returned as it is.
TableReader table_to_rgb(const TableReader& table, OutOfGamut* out_of_gamut = nullptr);

}  // namespace weft
