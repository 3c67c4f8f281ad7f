// The headline figures (verify/figures.h): the shape figure on curves with known answers, its
// gains and its split at 80 degrees, the paper's and the absolute figure, and their spread over
// batches and over the measurement's fits.
#include <gtest/gtest.h>

#include <cmath>

#include "weft/verify/figures.h"

namespace weft {
namespace {

// A measurement of one or more incidences at the given views, beta varying by point and channel.
MeasuredInplane geometry(std::vector<double> incidences, std::vector<double> views) {
  MeasuredInplane m;
  m.file = "synthetic";
  for (double ti : incidences) {
    MeasuredCurve c{ti, views, {}};
    for (size_t v = 0; v < views.size(); ++v)
      c.beta.push_back(Rgb(0.3 + 0.1 * v + 0.01 * ti, 0.05 + 0.02 * v, 0.02 + 0.005 * v));
    m.curves.push_back(c);
  }
  return m;
}

InplaneCurves reference(const MeasuredInplane& m) {
  return measured_fits(m)[0].beta;
}

// The measurement times exp(delta(incidence, view, channel)).
template <class F>
InplaneCurves offset(const InplaneCurves& measured, F delta) {
  InplaneCurves out = measured;
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t v = 0; v < out[i].size(); ++v)
      for (int k = 0; k < 3; ++k) out[i][v][k] *= std::exp(delta(i, v, k));
  return out;
}

TEST(VerifyFigures, ModelEqualToTheMeasurementTimesAGainPerChannelHasShapeZero) {
  const MeasuredInplane m = geometry({0, 30}, {-85, -80, -40, 0, 40, 80, 85});
  const InplaneCurves meas = reference(m);
  const Rgb c(2.0, 0.5, 3.0);
  InplaneCurves model = meas;
  for (auto& curve : model)
    for (auto& b : curve) b = b * c;
  ShapeFigure s = shape_figure(model, meas, m);
  EXPECT_NEAR(s.rms_log, 0, 1e-14);  // 0 but for rounding
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.gain[k], 1 / c[k], 1e-14);
  EXPECT_NEAR(s.rms_log_grazing, 0, 1e-14);
  // Views -80..80 are in (|view| <= 80 included): 5 views x 2 incidences x 3 channels.
  EXPECT_EQ(s.points, 30u);
  EXPECT_EQ(s.grazing_points, 12u);
  // A point where the model is zero is excluded from the gains and the RMS.
  model[1][3].g = 0;
  s = shape_figure(model, meas, m);
  EXPECT_EQ(s.excluded, 1u);
  EXPECT_EQ(s.points, 29u);
  EXPECT_NEAR(s.rms_log, 0, 1e-14);
  EXPECT_NEAR(s.gain.g, 1 / c.g, 1e-14);
}

TEST(VerifyFigures, KnownLogOffsetsGiveTheHandComputedShapeAndGains) {
  // One incidence, views -85, 0, 40, 85: the points in are views 0 and 40. ln(model / measured):
  //   R: 0.1, 0.3 -> ln g = -0.2, residuals -0.1, +0.1
  //   G: 0.5, 0.5 -> ln g = -0.5, residuals 0, 0
  //   B: -0.4, 0  -> ln g = +0.2, residuals -0.2, +0.2
  // RMS over the 6 points sqrt((0.01 + 0.01 + 0.04 + 0.04) / 6). Beyond 80 (views -85, 85):
  //   R 0.6, 0.2; G 0.5, -0.5; B 0.2, -0.2 -> with the same gains 0.4, 0; 0, -1; 0.4, 0:
  // RMS sqrt((0.16 + 1 + 0.16) / 6).
  const MeasuredInplane m = geometry({0}, {-85, 0, 40, 85});
  const double d[4][3] = {{0.6, 0.5, 0.2}, {0.1, 0.5, -0.4}, {0.3, 0.5, 0.0}, {0.2, -0.5, -0.2}};
  const InplaneCurves meas = reference(m);
  const ShapeFigure s =
      shape_figure(offset(meas, [&](size_t, size_t v, int k) { return d[v][k]; }), meas, m);
  EXPECT_NEAR(s.gain.r, std::exp(-0.2), 1e-12);
  EXPECT_NEAR(s.gain.g, std::exp(-0.5), 1e-12);
  EXPECT_NEAR(s.gain.b, std::exp(0.2), 1e-12);
  EXPECT_NEAR(s.rms_log, std::sqrt(0.1 / 6), 1e-12);
  EXPECT_NEAR(s.rms_log_channel[0], 0.1, 1e-12);
  EXPECT_NEAR(s.rms_log_channel[1], 0.0, 1e-12);
  EXPECT_NEAR(s.rms_log_channel[2], 0.2, 1e-12);
  ASSERT_EQ(s.rms_log_incidence.size(), 1u);
  EXPECT_NEAR(s.rms_log_incidence[0], s.rms_log, 1e-15);
  EXPECT_NEAR(s.rms_log_grazing, std::sqrt(1.32 / 6), 1e-12);
  EXPECT_EQ(s.points, 6u);
  EXPECT_EQ(s.grazing_points, 6u);
}

TEST(VerifyFigures, PaperAndAbsoluteFigures) {
  // The model is the measurement times e^0.3 everywhere but e^-0.1 at the normal point (view 0 of
  // incidence 0). Absolute: ln ratios 0.3 at 5 views and -0.1 at one, in every channel:
  // sqrt((5 * 0.09 + 0.01) / 6). The paper's factor e^0.1 makes them 0.4 and 0: sqrt(5 * 0.16 / 6).
  const MeasuredInplane m = geometry({0, 20}, {-40, 0, 40});
  const InplaneCurves meas = reference(m);
  const InplaneCurves model =
      offset(meas, [](size_t i, size_t v, int) { return i == 0 && v == 1 ? -0.1 : 0.3; });
  EXPECT_NEAR(absolute_figure(model, meas), std::sqrt((5 * 0.09 + 0.01) / 6), 1e-12);
  EXPECT_NEAR(paper_figure(model, meas, {0, 1}), std::sqrt(5 * 0.16 / 6), 1e-12);
  // No factor where the model is not positive at the normal point.
  InplaneCurves dark = model;
  dark[0][1].b = 0;
  EXPECT_TRUE(std::isnan(paper_figure(dark, meas, {0, 1})));
}

TEST(VerifyFigures, SpreadOverBatchesAndOverTheMeasurementsFits) {
  MeasuredInplane m = geometry({0}, {-40, 0, 40});
  const InplaneCurves meas = reference(m);
  // A second fit of the measurement: e^0.2 times the first.
  m.other_fits.push_back({"other", offset(meas, [](size_t, size_t, int) { return 0.2; })});
  // Two batches, e^0.1 and e^0.3 times the measurement: absolute figures 0.1 and 0.3, sample
  // standard deviation sqrt(0.01 + 0.01) = 0.1414, standard error 0.1414 / sqrt(2) = 0.1; the
  // shape of each is 0 (a constant factor).
  const std::vector<InplaneCurves> batches = {
      offset(meas, [](size_t, size_t, int) { return 0.1; }),
      offset(meas, [](size_t, size_t, int) { return 0.3; })};
  const double g = (std::exp(0.1) + std::exp(0.3)) / 2;  // the mean curves' factor
  const InplaneCurves mean = offset(meas, [&](size_t, size_t, int) { return std::log(g); });
  const ModelFigures f = model_figures(mean, batches, m, {0, 1});
  ASSERT_EQ(f.fits, (std::vector<std::string>{"nbrdf", "other"}));
  const FigureSamples& a = f.figure[kAbsoluteFigure];
  ASSERT_EQ(a.batch.size(), 2u);
  EXPECT_NEAR(a.batch[0][0], 0.1, 1e-12);
  EXPECT_NEAR(a.batch[0][1], 0.3, 1e-12);
  EXPECT_NEAR(a.batch[1][0], 0.1, 1e-12);  // |0.1 - 0.2| against the other fit
  EXPECT_NEAR(a.seed_sd(), std::sqrt(0.02), 1e-12);
  EXPECT_NEAR(a.seed_se(), 0.1, 1e-12);
  EXPECT_NEAR(a.value(), std::log(g), 1e-12);
  EXPECT_NEAR(a.mean[1], std::abs(std::log(g) - 0.2), 1e-12);
  EXPECT_NEAR(a.fit_min(), std::abs(std::log(g) - 0.2), 1e-12);
  EXPECT_NEAR(a.fit_max(), std::log(g), 1e-12);
  for (int k : {kShapeFigure, kPaperFigure}) {
    EXPECT_NEAR(f.figure[k].value(), 0, 1e-12) << k;
    EXPECT_NEAR(f.figure[k].seed_sd(), 0, 1e-12) << k;
  }
  // A deterministic model (no batches) has no seed spread.
  const ModelFigures d = model_figures(mean, {}, m, {0, 1});
  EXPECT_TRUE(d.figure[kAbsoluteFigure].batch.empty());
  EXPECT_EQ(d.figure[kAbsoluteFigure].seed_se(), 0.0);
}

TEST(VerifyFigures, FloorForLogRaisesEachChannelToAThousandthOfItsMaximum) {
  // R: 2, -0.5, 0 (max 2, floor 0.002: two raised); G: no positive value, so the brightest
  // channel's maximum (2) sets its floor, all three raised; B: 0.1..0.3, none below 0.0003.
  const InplaneCurves c = {{Rgb(2, -1, 0.1), Rgb(-0.5, -2, 0.2), Rgb(0, -3, 0.3)}};
  const LogFloored f = floor_for_log(c);
  EXPECT_EQ(f.floored, 5u);
  EXPECT_DOUBLE_EQ(f.curves[0][0].r, 2);
  EXPECT_DOUBLE_EQ(f.curves[0][1].r, kLogFloorFraction * 2);
  EXPECT_DOUBLE_EQ(f.curves[0][2].r, kLogFloorFraction * 2);
  for (int v = 0; v < 3; ++v) EXPECT_DOUBLE_EQ(f.curves[0][v].g, kLogFloorFraction * 2);
  EXPECT_DOUBLE_EQ(f.curves[0][2].b, 0.3);
  // No light at all: no floor, nothing changed, the points stay excluded.
  const LogFloored dark = floor_for_log({{Rgb(0.0), Rgb(-1.0)}});
  EXPECT_EQ(dark.floored, 0u);
  EXPECT_DOUBLE_EQ(dark.curves[0][1].g, -1);
}

TEST(VerifyFigures, SaturatedModelWithNegativeComponentsHasFiniteFigures) {
  // A model outside the gamut: its green is negative at every point, its red negative at one
  // (the normal point). Unfloored the paper's figure would not be defined; floored every figure
  // is, and the points raised are counted.
  const MeasuredInplane m = geometry({0, 30}, {-40, 0, 40});
  InplaneCurves model = reference(m);
  for (auto& curve : model)
    for (auto& b : curve) b.g = -0.01;
  model[0][1].r = -0.2;
  EXPECT_TRUE(std::isnan(paper_figure(model, reference(m), {0, 1})));
  const ModelFigures f = model_figures(model, {model, model}, m, {0, 1});
  EXPECT_EQ(f.log_floored_points, 7u);  // six greens and one red
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(std::isfinite(f.figure[k].value())) << kFigureKeys[k];
    EXPECT_TRUE(std::isfinite(f.figure[k].seed_se())) << kFigureKeys[k];
  }
  EXPECT_EQ(f.shape.excluded, 0u);
}

TEST(VerifyFigures, MeasuredFitSpreadIsTheLargestFigureBetweenTwoFits) {
  MeasuredInplane m = geometry({0}, {-40, 0, 40});
  const InplaneCurves meas = reference(m);
  // One fit: the spread is unknown.
  for (double s : measured_fit_spread(m, {0, 1})) EXPECT_TRUE(std::isnan(s));
  // Fits e^0.2 and e^-0.1 times the reference: absolute figures between the pairs 0.2, 0.1 and
  // 0.3; a constant factor has shape and paper's figure 0.
  m.other_fits.push_back({"up", offset(meas, [](size_t, size_t, int) { return 0.2; })});
  m.other_fits.push_back({"down", offset(meas, [](size_t, size_t, int) { return -0.1; })});
  const auto spread = measured_fit_spread(m, {0, 1});
  EXPECT_NEAR(spread[kAbsoluteFigure], 0.3, 1e-12);
  EXPECT_NEAR(spread[kShapeFigure], 0, 1e-12);
  EXPECT_NEAR(spread[kPaperFigure], 0, 1e-12);
  // A fit that bends (+-0.1 on the outer views) has a shape spread: RMS over 9 points of
  // (0.1 - 0.2/3, -0.2/3, 0.1 - 0.2/3) after the gain, per channel the same.
  m.other_fits.push_back(
      {"bent", offset(meas, [](size_t, size_t v, int) { return v == 1 ? 0.0 : 0.1; })});
  const double mean = 0.2 / 3, rms = std::sqrt((2 * (0.1 - mean) * (0.1 - mean) + mean * mean) / 3);
  EXPECT_NEAR(measured_fit_spread(m, {0, 1})[kShapeFigure], rms, 1e-12);
  EXPECT_EQ(normal_index(m)->view, 1u);
  EXPECT_FALSE(normal_index(geometry({30}, {0})).has_value());
}

}  // namespace
}  // namespace weft
