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
// The in-plane directions and the azimuth average: materials/table_inplane.h.
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/table_inplane.h"  // inplane_beta, table_to_rgb
#include "weft/verify/measured.h"

namespace weft {

// beta [incidence][view] of an RGB or spectral table at the measurement's views.
std::vector<std::vector<Rgb>> table_curves(const TabulatedBsdfTable& table,
                                           const MeasuredInplane& measured, int azimuths);

}  // namespace weft
