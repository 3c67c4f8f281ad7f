#include "weft/verify/metrics.h"

#include <cmath>
#include <limits>

#include "weft/core/error.h"

namespace weft {

void MetricsAccumulator::add(double model, double measured) {
  if (!(model > 0) || !(measured > 0)) {
    ++excluded;
    return;
  }
  const double l = std::log(model / measured), r = (model - measured) / measured;
  sum_log2 += l * l;
  sum_rel2 += r * r;
  ++points;
}

void MetricsAccumulator::add(const MetricsAccumulator& o) {
  sum_log2 += o.sum_log2;
  sum_rel2 += o.sum_rel2;
  points += o.points;
  excluded += o.excluded;
}

CurveMetrics MetricsAccumulator::result() const {
  CurveMetrics m;
  m.points = points;
  m.excluded = excluded;
  if (points) {
    m.rms_log = std::sqrt(sum_log2 / static_cast<double>(points));
    m.rms_rel = std::sqrt(sum_rel2 / static_cast<double>(points));
  } else {
    m.rms_log = m.rms_rel = std::numeric_limits<double>::quiet_NaN();
  }
  return m;
}

Rgb paper_normalization(const Rgb& model, const Rgb& measured) {
  Rgb f;
  for (int k = 0; k < 3; ++k)
    f[k] = model[k] > 0 ? measured[k] / model[k] : std::numeric_limits<double>::quiet_NaN();
  return f;
}

}  // namespace weft
