// The verdict (verify/verdict.h) on synthetic figures: resolved, and not resolved for each of its
// reasons (the measurement's fits disagree on the sign, the seed's error is too large, the batches
// disagree on the sign).
#include <gtest/gtest.h>

#include <cmath>

#include "weft/verify/verdict.h"

namespace weft {
namespace {

FigureSamples samples(std::vector<double> mean, std::vector<std::vector<double>> batch) {
  FigureSamples f;
  f.mean = std::move(mean);
  f.batch = std::move(batch);
  return f;
}

TEST(VerifyVerdict, ResolvedWhenEveryFitAndBatchAgreeAndTheDifferenceExceedsTheSeedError) {
  // Against the reference fit: batch differences -0.29, -0.31: mean -0.3, sample sd 0.01414,
  // standard error 0.01.
  const FigureSamples a = samples({0.3, 0.32, 0.35}, {{0.29, 0.31}, {0.31, 0.33}, {0.34, 0.36}});
  const FigureSamples b = samples({0.6, 0.65, 0.7}, {{0.58, 0.62}, {0.64, 0.66}, {0.69, 0.71}});
  const Verdict v = compare_figure(kShapeFigure, "computed_raytrace", "the computed model", a,
                                   "classic", "the classic model", b);
  EXPECT_TRUE(v.resolved);
  EXPECT_EQ(v.closer, "computed_raytrace");
  EXPECT_NEAR(v.difference, -0.3, 1e-12);
  EXPECT_NEAR(v.difference_seed_se, 0.01, 1e-12);
  ASSERT_EQ(v.difference_per_fit.size(), 3u);
  EXPECT_NEAR(v.difference_per_fit[2], -0.35, 1e-12);
  EXPECT_EQ(v.text,
            "Shape: the computed model is closer than the classic model (0.3 vs 0.6 RMS log, "
            "difference 0.3 +- 0.01 seed, same sign against all 3 fits of the measurement and "
            "every batch)");
  // The other way round: b is closer.
  const Verdict w = compare_figure(kShapeFigure, "classic", "the classic model", b,
                                   "computed_raytrace", "the computed model", a);
  EXPECT_TRUE(w.resolved);
  EXPECT_EQ(w.closer, "computed_raytrace");
  // The closer model's figure comes first in the words.
  EXPECT_NE(w.text.find("the computed model is closer than the classic model (0.3 vs 0.6"),
            std::string::npos)
      << w.text;
}

TEST(VerifyVerdict, NotResolvedWhenTheMeasurementsFitsDisagreeOnTheSign) {
  // a is closer against the reference and the second fit, farther against the third.
  const FigureSamples a = samples({0.3, 0.32, 0.75}, {{0.29, 0.31}, {0.31, 0.33}, {0.74, 0.76}});
  const FigureSamples b = samples({0.6, 0.65, 0.7}, {{0.58, 0.62}, {0.64, 0.66}, {0.69, 0.71}});
  const Verdict v = compare_figure(kPaperFigure, "a", "a", a, "b", "b", b);
  EXPECT_FALSE(v.resolved);
  EXPECT_FALSE(v.same_sign_fits);
  EXPECT_TRUE(v.closer.empty());
  EXPECT_NE(v.text.find("not resolved"), std::string::npos) << v.text;
  EXPECT_NE(v.text.find("the sign differs between the measurement's fits"), std::string::npos);
  EXPECT_EQ(v.text.rfind("Paper's one-point normalization", 0), 0u) << v.text;
}

TEST(VerifyVerdict, NotResolvedWithinTwoSeedStandardErrors) {
  // Batch differences -0.035, -0.005 (one sign): mean -0.02, sd 0.0212, standard error 0.015,
  // and 0.02 < 2 x 0.015.
  const FigureSamples a = samples({0.5}, {{0.485, 0.515}});
  const FigureSamples b = samples({0.52}, {{0.52, 0.52}});
  const Verdict v = compare_figure(kAbsoluteFigure, "a", "a", a, "b", "b", b);
  EXPECT_NEAR(v.difference_seed_se, 0.015, 1e-12);
  EXPECT_TRUE(v.same_sign_fits);
  EXPECT_TRUE(v.same_sign_batches);
  EXPECT_FALSE(v.exceeds_seed);
  EXPECT_FALSE(v.resolved);
  EXPECT_NE(v.text.find("within 2 seed standard errors"), std::string::npos) << v.text;
}

TEST(VerifyVerdict, NotResolvedWhenABatchDisagreesOnTheSign) {
  // A deterministic b (as the summation) against a's four batches; the difference of the mean
  // figures is -0.1.
  const FigureSamples a = samples({0.5}, {{0.38, 0.38, 0.38, 0.51}});
  const FigureSamples b = samples({0.6}, {});
  const Verdict v = compare_figure(kShapeFigure, "a", "a", a, "b", "b", b);
  // Batch differences -0.22, -0.22, -0.22, -0.09: sd 0.065, standard error 0.0325; 0.1 > 0.065,
  // all of one sign.
  EXPECT_TRUE(v.exceeds_seed);
  EXPECT_TRUE(v.same_sign_batches);
  EXPECT_TRUE(v.resolved);
  const FigureSamples c = samples({0.5}, {{0.45, 0.45, 0.45, 0.61}});
  // Differences -0.15 x 3, +0.01: sd 0.08, standard error 0.04; 0.1 > 0.08 but one batch is
  // farther than b.
  const Verdict w = compare_figure(kShapeFigure, "a", "a", c, "b", "b", b);
  EXPECT_TRUE(w.exceeds_seed);
  EXPECT_FALSE(w.same_sign_batches);
  EXPECT_FALSE(w.resolved);
  EXPECT_NE(w.text.find("the sign differs between batches"), std::string::npos) << w.text;
  // A figure that is not defined (a model dark at the normal point) resolves nothing.
  const Verdict n = compare_figure(kPaperFigure, "a", "a", samples({std::nan("")}, {}), "b", "b",
                                   samples({0.6}, {}));
  EXPECT_FALSE(n.resolved);
  EXPECT_NE(n.text.find("not defined"), std::string::npos) << n.text;
}

}  // namespace
}  // namespace weft
