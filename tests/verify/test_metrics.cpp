// The metrics (verify/metrics.h): curves with known answers and the paper's normalization.
#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"
#include "weft/verify/metrics.h"

using weft::testing::error_of;

namespace weft {
namespace {

TEST(VerifyMetrics, ConstantRatioGivesItsLogAndRelativeDifference) {
  // model = e^0.1 * measured at every point: ln ratio 0.1, relative difference e^0.1 - 1.
  MetricsAccumulator a;
  for (double m : {0.01, 0.3, 2.0, 7.5}) a.add(m * std::exp(0.1), m);
  const CurveMetrics r = a.result();
  EXPECT_EQ(r.points, 4u);
  EXPECT_EQ(r.excluded, 0u);
  EXPECT_NEAR(r.rms_log, 0.1, 1e-12);
  EXPECT_NEAR(r.rms_rel, std::exp(0.1) - 1, 1e-12);
}

TEST(VerifyMetrics, MixedRatiosAndExcludedPoints) {
  // ln ratios 0.3 and -0.4: RMS sqrt((0.09 + 0.16) / 2); relative e^0.3 - 1, e^-0.4 - 1.
  MetricsAccumulator a, b;
  a.add(std::exp(0.3), 1.0);
  b.add(2 * std::exp(-0.4), 2.0);
  b.add(0.0, 1.0);  // model zero: no log ratio
  b.add(1.0, 0.0);  // measurement zero
  a.add(b);
  const CurveMetrics r = a.result();
  EXPECT_EQ(r.points, 2u);
  EXPECT_EQ(r.excluded, 2u);
  EXPECT_NEAR(r.rms_log, std::sqrt(0.125), 1e-12);
  const double e1 = std::exp(0.3) - 1, e2 = std::exp(-0.4) - 1;
  EXPECT_NEAR(r.rms_rel, std::sqrt((e1 * e1 + e2 * e2) / 2), 1e-12);
  EXPECT_TRUE(std::isnan(MetricsAccumulator{}.result().rms_log));
}

TEST(VerifyMetrics, PaperNormalizationPerChannel) {
  const Rgb f = paper_normalization({2, 4, 8}, {1, 1, 2});
  EXPECT_DOUBLE_EQ(f.r, 0.5);
  EXPECT_DOUBLE_EQ(f.g, 0.25);
  EXPECT_DOUBLE_EQ(f.b, 0.25);
  // No factor where the model is zero there (a channel absorbed nearly whole): not defined, the
  // other channels keep theirs.
  const Rgb g = paper_normalization({1, 0, 2}, {1, 1, 1});
  EXPECT_DOUBLE_EQ(g.r, 1);
  EXPECT_TRUE(std::isnan(g.g));
  EXPECT_DOUBLE_EQ(g.b, 0.5);
}

}  // namespace
}  // namespace weft
