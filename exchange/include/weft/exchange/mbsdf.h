#pragma once
// A table as NVIDIA's measured BSDF file (.mbsdf), which MDL's bsdf_measurement() reads
// (df::measured_bsdf). Layout (little-endian): the line "NVIDIA ARC MBSDF V1\n", then per part the
// line "MBSDF_DATA_REFLECTION=\n" or "MBSDF_DATA_TRANSMISSION=\n" followed by uint32 type (0 one
// float, 1 three floats RGB), uint32 res_theta, uint32 res_phi and res_theta^2 res_phi values,
// index (theta_in res_theta + theta_out) res_phi + phi. The grid is isotropic: theta_in and
// theta_out in [0, pi/2), phi = |phi_out - phi_in| in [0, pi], each sample at the centre of its
// cell ((k + 1/2) of the step), as the MDL SDK's renderers look it up; transmission's theta_out
// is measured from the other side's normal. Values f in 1/sr: the table's isotropic average
// (TableView::isotropic, the table read with its sheen), in = towards the light (Weft's wi), out =
// towards the viewer. Reflection: light arriving on the upper side. Transmission: the MDL SDK's
// renderers orient the normal towards the viewer, so one transmission table serves light from
// either side, and they look up (f(in, out) + f(out, in)) / 2; the file holds the mean of the
// table's two directions (light from above to a view below, from below to a view above), made
// reciprocal the same way, and the report states how far that is from each direction. Spectral
// tables are written as linear sRGB (D65).
#include <filesystem>

#include "weft/exchange/export_report.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct MbsdfOptions {
  int theta_resolution = 45;  // per half circle: 2 deg steps
  int phi_resolution = 90;    // over [0, pi]
  // Rotations averaged for the isotropic table: 64, as the .bsdf (rgl_bsdf.h). Against the mean
  // over 256, an anisotropic woven table's reflection was 7.5 % off at the 95th percentile with 16
  // and 0.3 % with 64 (Mbsdf.SixtyFourRotationsHoldAnAnisotropicTable; docs/exchange.md).
  int azimuths = 64;
  void validate() const;  // weft::Error naming the field
};

ExportReport write_mbsdf(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                         const MbsdfOptions& options = {});

}  // namespace weft
