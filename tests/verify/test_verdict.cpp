// The verdict (verify/verdict.h) on synthetic figures: resolved, and a tie for each of its
// reasons (the measurement's fits disagree on the sign, the difference is within the
// measurement's own spread or within the seed's error, the batches disagree on the sign); one
// fit needs the smallest spread between fits seen on the bundled MERL data; no model named where
// none describes the sample. And that smallest spread, recomputed from the bundled data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "weft/verify/measured.h"
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
  // The measurement's own spread 0.06: the difference is five times it.
  const VerdictContext spread{0.06, false};
  const Verdict v = compare_figure(kShapeFigure, "computed_raytrace", "the computed model", a,
                                   "classic", "the classic model", b, spread);
  EXPECT_TRUE(v.resolved);
  EXPECT_EQ(v.closer, "computed_raytrace");
  EXPECT_NEAR(v.difference, -0.3, 1e-12);
  EXPECT_NEAR(v.difference_seed_se, 0.01, 1e-12);
  ASSERT_EQ(v.difference_per_fit.size(), 3u);
  EXPECT_NEAR(v.difference_per_fit[2], -0.35, 1e-12);
  EXPECT_EQ(v.text,
            "Shape: the computed model is closer than the classic model (0.3 vs 0.6 RMS log, "
            "difference 0.3 +- 0.01 seed, above the measurement's own spread 0.06 between its 3 "
            "fits, same sign against all 3 fits of the measurement and every batch)");
  EXPECT_TRUE(v.exceeds_spread);
  EXPECT_FALSE(v.tie);
  // The other way round: b is closer.
  const Verdict w = compare_figure(kShapeFigure, "classic", "the classic model", b,
                                   "computed_raytrace", "the computed model", a, spread);
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
  const Verdict v = compare_figure(kPaperFigure, "a", "a", a, "b", "b", b, {0.01, false});
  EXPECT_FALSE(v.resolved);
  EXPECT_TRUE(v.tie);
  EXPECT_FALSE(v.same_sign_fits);
  EXPECT_TRUE(v.closer.empty());
  EXPECT_NE(v.text.find("a tie"), std::string::npos) << v.text;
  EXPECT_NE(v.text.find("the sign differs between the measurement's fits"), std::string::npos);
  EXPECT_EQ(v.text.rfind("Paper's one-point normalization", 0), 0u) << v.text;
}

TEST(VerifyVerdict, NotResolvedWithinTwoSeedStandardErrors) {
  // Batch differences -0.035, -0.005 (one sign): mean -0.02, sd 0.0212, standard error 0.015,
  // and 0.02 < 2 x 0.015; a spread of 0.01 (given as known) is exceeded.
  const FigureSamples a = samples({0.5}, {{0.485, 0.515}});
  const FigureSamples b = samples({0.52}, {{0.52, 0.52}});
  const Verdict v = compare_figure(kAbsoluteFigure, "a", "a", a, "b", "b", b, {0.01, false});
  EXPECT_TRUE(v.exceeds_spread);
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
  const VerdictContext spread{0.05, false};
  const Verdict v = compare_figure(kShapeFigure, "a", "a", a, "b", "b", b, spread);
  // Batch differences -0.22, -0.22, -0.22, -0.09: sd 0.065, standard error 0.0325; 0.1 > 0.065,
  // all of one sign.
  EXPECT_TRUE(v.exceeds_seed);
  EXPECT_TRUE(v.same_sign_batches);
  EXPECT_TRUE(v.resolved);
  const FigureSamples c = samples({0.5}, {{0.45, 0.45, 0.45, 0.61}});
  // Differences -0.15 x 3, +0.01: sd 0.08, standard error 0.04; 0.1 > 0.08 but one batch is
  // farther than b.
  const Verdict w = compare_figure(kShapeFigure, "a", "a", c, "b", "b", b, spread);
  EXPECT_TRUE(w.exceeds_seed);
  EXPECT_FALSE(w.same_sign_batches);
  EXPECT_FALSE(w.resolved);
  EXPECT_NE(w.text.find("the sign differs between batches"), std::string::npos) << w.text;
  // A figure that is not defined (a model dark at the normal point) resolves nothing.
  const Verdict n = compare_figure(kPaperFigure, "a", "a", samples({std::nan("")}, {}), "b", "b",
                                   samples({0.6}, {}), spread);
  EXPECT_FALSE(n.resolved);
  EXPECT_FALSE(n.tie);
  EXPECT_NE(n.text.find("not defined"), std::string::npos) << n.text;
}

TEST(VerifyVerdict, ATieWithinTheMeasurementsOwnSpread) {
  // A difference of 0.05 with a seed error of 0.001 and one sign everywhere, against a
  // measurement whose fits are 0.06 apart: the choice of fit could turn it.
  const FigureSamples a = samples({0.30, 0.31}, {{0.299, 0.301}, {0.309, 0.311}});
  const FigureSamples b = samples({0.35, 0.36}, {{0.35, 0.35}, {0.36, 0.36}});
  const Verdict v =
      compare_figure(kShapeFigure, "a", "the a model", a, "b", "the b model", b, {0.06, false});
  EXPECT_TRUE(v.same_sign_fits);
  EXPECT_TRUE(v.same_sign_batches);
  EXPECT_TRUE(v.exceeds_seed);
  EXPECT_FALSE(v.exceeds_spread);
  EXPECT_FALSE(v.resolved);
  EXPECT_TRUE(v.tie);
  EXPECT_TRUE(v.closer.empty());
  EXPECT_DOUBLE_EQ(v.spread_required, 0.06);
  EXPECT_NE(v.text.find("Shape, the a model vs the b model: a tie"), std::string::npos) << v.text;
  EXPECT_NE(v.text.find("within the measurement's own spread 0.06 between its 2 fits"),
            std::string::npos)
      << v.text;
  // Twice as far apart, the same difference exceeds a spread of 0.04.
  EXPECT_TRUE(compare_figure(kShapeFigure, "a", "a", a, "b", "b", b, {0.04, false}).resolved);
}

TEST(VerifyVerdict, OneFitNeedsTheSmallestSpreadOfTheBundledMeasurements) {
  // The case of one measured fit: a difference of 0.022 with a tiny seed error is no verdict when
  // the bundled MERL measurements' fits already differ by more than that.
  ASSERT_GT(kMinBundledFitSpread[kShapeFigure], 0.022);
  const FigureSamples a = samples({0.300}, {{0.2999, 0.3001}});
  const FigureSamples b = samples({0.322}, {{0.3219, 0.3221}});
  const Verdict v = compare_figure(kShapeFigure, "a", "a", a, "b", "b", b, {});
  EXPECT_TRUE(std::isnan(v.measured_spread));
  EXPECT_DOUBLE_EQ(v.spread_required, kMinBundledFitSpread[kShapeFigure]);
  EXPECT_TRUE(v.exceeds_seed);
  EXPECT_FALSE(v.resolved);
  EXPECT_TRUE(v.tie);
  EXPECT_NE(v.text.find("one fit: spread unknown"), std::string::npos) << v.text;
  // A difference beyond it is resolved, and says what stood in for the spread.
  const double d = 2 * kMinBundledFitSpread[kShapeFigure];
  const FigureSamples c = samples({0.3 + d}, {{0.2999 + d, 0.3001 + d}});
  const Verdict w = compare_figure(kShapeFigure, "a", "a", a, "c", "c", c, {});
  EXPECT_TRUE(w.resolved);
  EXPECT_EQ(w.closer, "a");
  EXPECT_NE(w.text.find("one fit: spread unknown; above"), std::string::npos) << w.text;
}

TEST(VerifyVerdict, NoModelNamedWhereNoneDescribesTheSample) {
  // A glossy film: every model 2.0 to 2.4 in shape.
  EXPECT_TRUE(no_model_describes({2.0, 2.4, 2.2}));
  EXPECT_FALSE(no_model_describes({2.0, 0.9}));  // one model does
  EXPECT_FALSE(no_model_describes({1.0, 2.0}));  // 1.0 itself is not above
  EXPECT_FALSE(no_model_describes({}));
  EXPECT_FALSE(no_model_describes({std::nan("")}));
  EXPECT_TRUE(no_model_describes({std::nan(""), 1.5}));
  // A difference that would otherwise be resolved names no closer model.
  const FigureSamples a = samples({2.0}, {{1.999, 2.001}});
  const FigureSamples b = samples({2.4}, {{2.399, 2.401}});
  const Verdict v =
      compare_figure(kShapeFigure, "a", "the a model", a, "b", "the b model", b, {0.06, true});
  EXPECT_TRUE(v.exceeds_spread);
  EXPECT_TRUE(v.exceeds_seed);
  EXPECT_FALSE(v.resolved);
  EXPECT_FALSE(v.tie);
  EXPECT_TRUE(v.no_model_describes);
  EXPECT_TRUE(v.closer.empty());
  EXPECT_NE(v.text.find("no model here describes the sample"), std::string::npos) << v.text;
}

// kMinBundledFitSpread recomputed: each bundled MERL measurement's spread between its three fits
// (nbrdf, sgd, abc: materials/data/measured/README.md), the smallest over the measurements per
// figure. The constant states it to 3 decimals, so it must agree to 5e-4. Printed, so this test
// is the command that measures it.
TEST(VerifyVerdict, BundledFitSpreadIsTheSmallestOverTheMerlMeasurements) {
  const std::filesystem::path dir = bundled_measured_inplane().parent_path().parent_path();
  std::array<double, 3> smallest{INFINITY, INFINITY, INFINITY};
  int measurements = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    const std::filesystem::path table = entry.path() / "inplane.csv";
    if (name.rfind("merl-", 0) != 0 || !std::filesystem::exists(table)) continue;
    const MeasuredInplane m = read_measured_inplane(table);
    ASSERT_EQ(measured_fits(m).size(), 3u) << name;
    const std::array<double, 3> spread = measured_fit_spread(m, normal_index(m).value());
    std::printf("  %-28s shape %.4f  paper_normalized %.4f  absolute %.4f\n", name.c_str(),
                spread[0], spread[1], spread[2]);
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(spread[k])) << name << " " << kFigureKeys[k];
      smallest[k] = std::min(smallest[k], spread[k]);
    }
    ++measurements;
  }
  EXPECT_EQ(measurements, 13);  // the bundled MERL fabrics (materials/data/measured/)
  for (int k = 0; k < 3; ++k) {
    std::printf("  smallest %s %.4f\n", kFigureKeys[k], smallest[k]);
    EXPECT_NEAR(kMinBundledFitSpread[k], smallest[k], 5e-4) << kFigureKeys[k];
  }
}

}  // namespace
}  // namespace weft
