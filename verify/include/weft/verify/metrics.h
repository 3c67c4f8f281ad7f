#pragma once
// The metrics that compare a model's in-plane curves with the measurement: absolute, and with the
// paper's normalization (Voloboy et al. 2010, section 4).
#include <cstddef>
#include <string>

#include "weft/core/spectrum.h"

namespace weft {

// model vs measurement over points where both are positive: RMS of ln(model / measured) and of
// (model - measured) / measured. Points where either is <= 0 are not in the RMS and are counted
// in 'excluded' (a log ratio is undefined there).
struct CurveMetrics {
  double rms_log = 0, rms_rel = 0;
  size_t points = 0, excluded = 0;
};

// Accumulates squared errors of points; 'result' gives the RMS over what was added.
struct MetricsAccumulator {
  double sum_log2 = 0, sum_rel2 = 0;
  size_t points = 0, excluded = 0;
  void add(double model, double measured);
  void add(const MetricsAccumulator& other);
  CurveMetrics result() const;
};

// The paper's normalization, per channel: the factor that makes the model's beta at normal
// incidence and normal view equal the measured one. NaN in a channel where the model's value is
// not positive there (no factor exists: a fabric that absorbs a channel nearly whole, traced with
// few particles, can leave that one bin empty); the paper's figure is then not defined.
Rgb paper_normalization(const Rgb& model_at_normal, const Rgb& measured_at_normal);

}  // namespace weft
