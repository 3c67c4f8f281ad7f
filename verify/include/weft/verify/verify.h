#pragma once
// weft verify (docs/verify.md): the paper's verification (Voloboy et al. 2010, section 4). The
// in-plane radiance coefficient beta = pi f of the computed fabric and of a classic baseline,
// against a measured in-plane table, with the metrics that compare them, the fabric's colour
// (paper's Table 1), a fit of each model's fiber, renders of the sample and the report files.
// This header gathers the library's headers, in the order of the data.
// clang-format off
#include "weft/verify/measured.h"  // the measurement
#include "weft/verify/inplane.h"   // a table's beta in the plane of incidence
#include "weft/verify/metrics.h"   // the metrics, absolute and normalized
#include "weft/verify/figures.h"   // the headline figures: shape, paper's, absolute
#include "weft/verify/verdict.h"   // which model is closer, and whether that is resolved
#include "weft/verify/colour.h"    // the colour table
#include "weft/verify/settings.h"  // the quality levels
#include "weft/verify/classic.h"   // the classic fiber from a baked fiber table
#include "weft/verify/fit.h"       // the fit of a model's fiber
#include "weft/verify/render.h"    // the renders of the sample
#include "weft/verify/run.h"       // the run
#include "weft/verify/report.h"    // the report's files
// clang-format on
