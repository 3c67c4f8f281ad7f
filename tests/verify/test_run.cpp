// The run (verify/run.h): the same bits at any thread count, the classic colour from the volume
// albedo, and the measurement's normal point.
#include <gtest/gtest.h>

#include "constant_table.h"
#include "test_util.h"
#include "weft/core/math.h"
#include "weft/materials/registry.h"
#include "weft/verify/classic.h"
#include "weft/verify/report.h"
#include "weft/verify/run.h"

using weft::testing::constant_table;
using weft::testing::error_of;

namespace weft {
namespace {

// A small run on the bundled poplin at fiber detail: a grey fiber table of 'fiber_albedo', a
// classic fiber of volume albedo 0.6, a flat measurement of 0.2 at normal incidence.
struct SmallRun {
  WovenSample sample;
  VerifySettings settings;
  VerifyInputs inputs;
  MeasuredInplane measured;
};

SmallRun small_run(double fiber_albedo) {
  WeaveOptions w;
  w.detail = "fiber";
  SmallRun r{make_woven_sample(overlay(red_cotton_weave_options(), w)),
             verify_settings(VerifyQuality::kDraft),
             {},
             {}};
  r.settings.resolution = 2;
  r.settings.particles_per_bin = 200;
  r.settings.batches = 2;
  r.settings.azimuths = 3;
  r.inputs.fiber = constant_table(2, kNumBands, fiber_albedo);
  r.inputs.volume_albedo.fill(0.6);
  r.inputs.classic_distribution = {MicrofacetModel::kBeckmann, 0.35};
  r.inputs.classic_ior = 1.557;
  r.measured.file = "synthetic";
  r.measured.curves.push_back({0, {-30, 0, 30}, {Rgb(0.2), Rgb(0.2), Rgb(0.2)}});
  return r;
}

TEST(VerifyRun, SameBitsAtAnyThreadCountAndClassicFromTheVolumeAlbedo) {
  SmallRun run = small_run(0.2);
  const WovenSample& sample = run.sample;
  VerifySettings& s = run.settings;
  s.summation_samples = 2;
  const VerifyInputs& in = run.inputs;
  MeasuredInplane& m = run.measured;
  m.curves.push_back({30, {-30, 0, 30}, {Rgb(0.2), Rgb(0.2), Rgb(0.2)}});
  std::string first;
  for (int threads : {1, 2}) {
    s.threads = threads;
    VerifyReport r = run_verify(sample, in, m, s);
    ASSERT_FALSE(r.cancelled);
    ASSERT_EQ(r.models.size(), 2u);  // ray trace and classic (no summation given)
    // A flat volume albedo of 0.6 is grey 0.6 in linear sRGB, over the share past the lobe.
    const double entering = classic_entering_fraction(in.classic_distribution, in.classic_ior);
    EXPECT_NEAR(r.classic_reflectance.r, 0.6 / entering, 2e-3);
    EXPECT_NEAR(r.classic_reflectance.b, 0.6 / entering, 2e-3);
    ASSERT_GE(r.colours.size(), 2u);
    // Per curve (incidence, channel): their points add up to the incidence's.
    for (const auto& mc : r.models)
      for (size_t i = 0; i < m.curves.size(); ++i) {
        size_t points = 0;
        for (const auto& c : mc.normalized_channel[i]) points += c.points + c.excluded;
        EXPECT_EQ(points, mc.normalized[i].points + mc.normalized[i].excluded);
        EXPECT_EQ(points, 3u * m.curves[i].view_deg.size());
      }
    // Both ray-traced models keep each batch's curves and score them: one figure per batch.
    for (const auto& mc : r.models) {
      ASSERT_EQ(mc.batch_beta.size(), 2u) << mc.key;
      EXPECT_EQ(mc.figures.fits, std::vector<std::string>{"nbrdf"});
      EXPECT_EQ(mc.figures.figure[kShapeFigure].batch.at(0).size(), 2u);
      // The figures are of the curves floored for the logs (figures.h floor_for_log).
      EXPECT_EQ(mc.figures.shape.rms_log,
                shape_figure(floor_for_log(mc.beta).curves,
                             floor_for_log(measured_fits(m)[0].beta).curves, m)
                    .rms_log);
    }
    EXPECT_EQ(r.colours[0].name, "computed fabric, reflection");
    r.seconds.clear();
    r.settings.threads = 0;
    const std::string csv = verify_inplane_csv(r) + verify_metrics_json(r);
    if (threads == 1)
      first = csv;
    else
      EXPECT_EQ(csv, first);
  }
  // The measurement must hold normal incidence and view.
  m.curves.erase(m.curves.begin());
  EXPECT_NE(error_of([&] { run_verify(sample, in, m, s); }).find("theta_i_deg"), std::string::npos);
}

// A fiber that returns no light leaves the ray trace with no light in any channel: no floor
// exists for its logs (figures.h floor_for_log), so the paper's factor and figure are not defined
// (null in metrics.json) while the run and the other model's figures go on. (A channel with light
// somewhere but an empty normal bin is floored and has its factor.)
TEST(VerifyRun, PaperFigureNotDefinedWhereTheModelsNormalBinIsEmpty) {
  SmallRun run = small_run(0.0);
  run.settings.threads = 2;
  const VerifyReport r = run_verify(run.sample, run.inputs, run.measured, run.settings);
  ASSERT_EQ(r.models.size(), 2u);
  const ModelCurves& computed = r.models[0];
  const ModelCurves& classic = r.models[1];
  ASSERT_EQ(computed.key, "computed_raytrace");
  EXPECT_TRUE(std::isnan(computed.normalization.r));
  EXPECT_TRUE(std::isnan(computed.normalized_overall.rms_log));
  EXPECT_TRUE(std::isnan(computed.normalized[0].rms_log));
  EXPECT_TRUE(std::isfinite(classic.normalized_overall.rms_log));
  const std::string json = verify_metrics_json(r);
  EXPECT_NE(json.find("\"computed_rms_log\": null"), std::string::npos);
}

// A saturated fiber (it scatters only the 490 nm band, far outside the sRGB gamut: its linear
// sRGB red is negative): nothing is clipped, the out-of-gamut components are counted, and every
// model's figures and the paper's factor are defined (the log figures floor what is not positive,
// and count it).
TEST(VerifyRun, SaturatedColourIsNotClippedAndItsFiguresAreDefined) {
  SmallRun run = small_run(0.0);
  run.inputs.fiber = TabulatedBsdfTable::from_function(
      2, kNumBands,
      [](const Vec3&, const Vec3&, std::span<double> v) {
        for (double& x : v) x = 0;
        v[10] = 0.2 / kPi;  // 490 nm, total albedo 0.4
      },
      2, 1, 1);
  run.settings.threads = 2;
  const VerifyReport r = run_verify(run.sample, run.inputs, run.measured, run.settings);
  EXPECT_EQ(r.fabric_table_gamut_clipped, 0u);
  EXPECT_GT(r.fabric_table_out_of_gamut.components, 0u);
  const ModelCurves& computed = r.models.at(0);
  ASSERT_EQ(computed.key, "computed_raytrace");
  EXPECT_GT(computed.figures.log_floored_points, 0u);
  for (const ModelCurves& m : r.models) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(std::isfinite(m.figures.figure[k].value())) << m.key << " " << kFigureKeys[k];
      EXPECT_TRUE(std::isfinite(m.normalization[k])) << m.key;
    }
    EXPECT_TRUE(std::isfinite(m.normalized_overall.rms_log)) << m.key;
  }
  const auto j = verify_metrics(r);
  EXPECT_EQ(j.at("fabric_table_gamut_clipped_components"), 0);
  EXPECT_EQ(j.at("fabric_table_out_of_gamut_components"), r.fabric_table_out_of_gamut.components);
  EXPECT_EQ(j.at("models").at("computed_raytrace").at("log_floored_points"),
            computed.figures.log_floored_points);
}

}  // namespace
}  // namespace weft
