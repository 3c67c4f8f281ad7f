// weft verify's request and plan (verify/plan.h): the request's defaults are the library's, the
// plan reads and checks the inputs before any work, a sharded job's request comes back from its
// parts, and the estimate grows with the fit.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "test_util.h"
#include "weft/verify/plan.h"

namespace fs = std::filesystem;
using weft::testing::error_of;

namespace weft {
namespace {

TEST(VerifyPlan, RequestDefaultsAreTheLibrarys) {
  const VerifyRequest r;
  EXPECT_EQ(r.fiber, "red-cotton");
  EXPECT_EQ(r.quality, "default");
  EXPECT_EQ(parse_verify_quality(r.quality), VerifySettings{}.quality);
  EXPECT_EQ(r.seed, VerifySettings{}.seed);
  EXPECT_EQ(r.threads, 0);
  EXPECT_EQ(r.fit_params,
            "dye_scale,particle_fraction_scale,particle_radius_scale,roughness_alpha");
  EXPECT_EQ(r.fit_evaluations, FitOptions{}.max_evaluations);
  EXPECT_EQ(parse_fit_inner(r.fit_inner), FitInner::kRaytrace);
  EXPECT_EQ(parse_fit_method(r.fit_method), FitMethod::kLevenbergMarquardt);
}

TEST(VerifyPlan, ReadsTheInputsOfADraftRun) {
  VerifyRequest r;
  r.quality = "draft";
  r.seed = 7;
  r.threads = 2;
  const VerifyPlan p = plan_verify(r);
  EXPECT_EQ(p.settings.quality, VerifyQuality::kDraft);
  EXPECT_EQ(p.settings.seed, 7u);
  EXPECT_EQ(p.settings.threads, 2);
  EXPECT_EQ(p.measured_path, bundled_measured_inplane());
  EXPECT_EQ(p.measured.curves.size(), 9u);
  EXPECT_EQ(p.spec.name, "red-cotton");
  EXPECT_FALSE(p.fiber_table);
  EXPECT_FALSE(p.shard);
  EXPECT_EQ(p.weave.detail, "fiber");  // the fiber-level reference
  EXPECT_TRUE(p.fit_names.empty());
  // The bundled table's colour space, from its comment line; --colour-space over it.
  EXPECT_EQ(p.measured.colour_space, MeasuredColourSpace::kCamera);
  r.colour_space = "srgb";
  EXPECT_EQ(plan_verify(r).measured.colour_space, MeasuredColourSpace::kSrgb);
}

TEST(VerifyPlan, BadRequestsAreRefusedNamingTheOption) {
  struct Case {
    std::function<void(VerifyRequest&)> set;
    std::string words;
  };
  const std::vector<Case> cases = {
      {[](VerifyRequest& r) { r.fit_params_given = true; },
       "field '--fit-params': only with --fit"},
      {[](VerifyRequest& r) { r.fit_method_given = true; },
       "field '--fit-method': only with --fit"},
      {[](VerifyRequest& r) { r.fit_seeds_given = true; }, "field '--fit-seeds': only with --fit"},
      {[](VerifyRequest& r) { r.fit = true, r.fit_seeds = 0; },
       "field '--fit-seeds': 0 is outside 1 to 16"},
      {[](VerifyRequest& r) { r.fit = true, r.shard = "0/2"; }, "not with --shard"},
      {[](VerifyRequest& r) { r.fit = true, r.fit_params = "dye_scale,hue"; },
       "'hue' is not one of"},
      {[](VerifyRequest& r) { r.pattern = "plain", r.wif = "x.wif"; }, "--wif"},
      {[](VerifyRequest& r) { r.classic_albedo = "0.3,0.2"; }, "--classic-albedo"},
      {[](VerifyRequest& r) { r.shard = "3/2"; }, "--shard"},
      {[](VerifyRequest& r) { r.colour_space = "xyz"; }, "field '--colour-space'"},
      {[](VerifyRequest& r) { r.fiber = "no-such-fiber"; }, "no-such-fiber"},
      {[](VerifyRequest& r) { r.colour = "lab:40,20,10", r.colour_from = "measured"; },
       "field '--colour-from': give --colour or --colour-from, not both"},
      {[](VerifyRequest& r) { r.colour_from = "swatch"; }, "must be 'measured', got 'swatch'"},
      {[](VerifyRequest& r) { r.colour = "lab:40,20"; }, "field '--colour'"},
      {[](VerifyRequest& r) { r.colour = "lab:40,20,10", r.fit = true; },
       "the fit sets the colour itself"},
      {[](VerifyRequest& r) { r.colour_from = "measured", r.shard = "0/2"; },
       "would solve the colour in every shard"}};
  for (const auto& c : cases) {
    VerifyRequest r;
    r.quality = "draft";
    c.set(r);
    const std::string e = error_of([&] { plan_verify(r); });
    EXPECT_NE(e.find(c.words), std::string::npos) << c.words << ": " << e;
  }
}

// --colour-from measured reads the measurement's neural fit at 8 degrees: the bundled MERL red
// fabric's reading is red (its red channel the largest) and a reflectance.
TEST(VerifyPlan, ColourFromTheMeasurementIsItsD8Reading) {
  VerifyRequest r;
  r.quality = "draft";
  r.colour_from = "measured";
  const VerifyPlan p = plan_verify(r);
  ASSERT_TRUE(p.colour);
  EXPECT_EQ(p.colour->spec, "measured:merl-red-fabric");
  EXPECT_GT(p.colour->lab.a, 20);  // red
  EXPECT_GT(p.colour->lab.l, 10);
  EXPECT_LT(p.colour->lab.l, 90);
}

// A dye's concentration moves the hue: a fit of it is refused against the bundled measurement,
// whose colour space (camera RGB) is not the tables', and planned when the measurement is sRGB.
TEST(VerifyPlan, DyeConcentrationsFitOnlyWhereColourIsComparable) {
  VerifyRequest r;
  r.quality = "draft";
  r.fit = true;
  r.fit_params = "dye0_concentration";
  EXPECT_NE(error_of([&] { plan_verify(r); }).find("colour space is camera"), std::string::npos);
  r.fit_params = "dye_scale";  // the recipe's depth, its hue kept
  EXPECT_NO_THROW(plan_verify(r));
  r.fit_params = "dye0_concentration";
  r.colour_space = "srgb";
  EXPECT_EQ(plan_verify(r).fit_names, std::vector<std::string>{"dye0_concentration"});
}

TEST(VerifyPlan, ClassicAlbedoIsThreeReflectances) {
  const Rgb c = parse_classic_albedo("0.3,0.05,1");
  EXPECT_EQ(c.r, 0.3);
  EXPECT_EQ(c.g, 0.05);
  EXPECT_EQ(c.b, 1.0);
  for (const char* bad :
       {"0.3,0.2", "0.3,0.2,0.1,0", "0.3,x,0.1", "-0.1,0,0", "1.5,0,0", "nan,0,0"})
    EXPECT_NE(error_of([&] { parse_classic_albedo(bad); }).find("--classic-albedo"),
              std::string::npos)
        << bad;
}

// A shard's job names its options; the merge's request, made from them, plans the same job.
TEST(VerifyPlan, AJobsRequestPlansTheSameJob) {
  VerifyRequest r;
  r.quality = "draft";
  r.seed = 5;
  r.threads = 3;
  r.pattern = "twill:2/1";
  r.colour_space = "srgb";
  r.shard = "1/4";
  r.output = "part-1.part";
  const VerifyPlan p = plan_verify(r);
  ASSERT_TRUE(p.shard);
  const JobPart job = verify_job(p, *p.shard);
  EXPECT_EQ(job.command, "verify");
  EXPECT_EQ(job.shard.index, 1u);
  EXPECT_EQ(job.shard.count, 4u);
  EXPECT_EQ(job.units_total, verify_traces(p.settings).size() *
                                 uint64_t(2 * p.settings.resolution * p.settings.resolution));
  const VerifyRequest again = verify_job_request(job, "report");
  EXPECT_EQ(again.output, "report");
  EXPECT_EQ(again.threads, 3);
  EXPECT_EQ(again.pattern, "twill:2/1");
  EXPECT_EQ(again.colour_space, "srgb");
  EXPECT_TRUE(again.shard.empty());
  EXPECT_EQ(job_difference(job, verify_job(plan_verify(again), job.shard)), "");
}

// A part is a user's file: a merge that reads a verify job's options names the one of the wrong
// type or missing, instead of the JSON library's message.
TEST(VerifyPlan, AJobsRequestNamesABadOption) {
  VerifyRequest r;
  r.quality = "draft";
  r.shard = "0/2";
  const VerifyPlan p = plan_verify(r);
  ASSERT_TRUE(p.shard);
  const JobPart job = verify_job(p, *p.shard);
  EXPECT_EQ(verify_job_request(job, "out").wif, "");  // an unset option is stored empty
  for (const char* key :
       {"fiber", "measured", "weave", "pattern", "wif", "quality", "colour_space"}) {
    JobPart bad = job;
    bad.job["options"][key] = 3;
    EXPECT_NE(error_of([&] {
                verify_job_request(bad, "out");
              }).find(std::string("field 'job.options.") + key + "': must be a string"),
              std::string::npos)
        << key;
  }
  JobPart missing = job;
  missing.job["options"].erase("quality");
  EXPECT_NE(error_of([&] {
              verify_job_request(missing, "out");
            }).find("field 'job.options.quality': is required"),
            std::string::npos);
  JobPart no_options = job;
  no_options.job["options"] = "draft";
  EXPECT_NE(error_of([&] { verify_job_request(no_options, "out"); }).find("field 'job.options'"),
            std::string::npos);
}

TEST(VerifyPlan, EstimateGrowsWithTheFit) {
  VerifyRequest r;
  r.quality = "draft";
  r.threads = 2;
  const VerifyPlan p = plan_verify(r);
  const VerifyEstimate e = estimate_verify(p);
  EXPECT_EQ(e.cores, 2u);
  EXPECT_GT(e.photons, 0);  // the spec is baked
  EXPECT_GT(e.particles, 0);
  EXPECT_GT(e.typical, e.least);
  const VerifyEstimate fit = estimate_verify(p.settings, true, true, 100, 4, 1);
  EXPECT_GT(fit.photons, e.photons);
  EXPECT_GT(fit.particles, e.particles);
  // Each further inner seed adds a fit and judges every fit at it.
  const VerifyEstimate seeds = estimate_verify(p.settings, true, true, 100, 4, 3);
  EXPECT_GT(seeds.photons, fit.photons);
  EXPECT_GT(seeds.typical, fit.typical);
  // A baked table is not baked again.
  EXPECT_EQ(estimate_verify(p.settings, false, false, 0, 0, 1).photons, 0);
}

// The sample's own cost: the 8452 draft (84 x 100 threads) at draft quality took 191 s of CPU,
// 3.2 GB at its peak, against 20.0 s for the bundled poplin (/usr/bin/time, --threads 2, the
// 2-core machine near idle, 2026-12-06; 325 and 35 s on 2026-12-05, before the light groups and
// the faster plots), and its estimate was once the poplin's
// (docs/verify.md "Time"). Each estimate within twice its measurement, the scene's memory too: an
// upper bound
// (5.5 GB), counted on the fibers the sample will hold in the vertical sections it falls back to
// (4.0 M segments at packing 0.31; at the default packing 0.55 it was 9.7 GB, 3 times the peak).
TEST(VerifyPlan, EstimateCoversTheSamplesSize) {
  VerifyRequest r;
  r.quality = "draft";
  r.threads = 2;
  const VerifyEstimate poplin = estimate_verify(plan_verify(r));
  r.wif = (fs::path(WEFT_SOURCE_DIR) / "scenes/data/wif/8452.wif").string();
  const VerifyEstimate large = estimate_verify(plan_verify(r));
  for (const auto& [e, measured] : {std::pair{poplin, 20.0}, std::pair{large, 191.0}}) {
    EXPECT_GT(e.typical, measured / 2);
    EXPECT_LT(e.typical, measured * 2);
  }
  EXPECT_GT(large.fiber_segments, 500 * poplin.fiber_segments);
  EXPECT_LT(large.fiber_segments, 4.1e6);
  EXPECT_GT(large.scene_bytes, 3.2e9);
  EXPECT_LT(large.scene_bytes, 2 * 3.2e9);
  // Only what the sample costs grows: the particles are the quality's.
  EXPECT_EQ(large.particles, poplin.particles);
}

// A felt's rays walk long: the bundled suite's felts took 4.7-5.7x the time of a poplin of the
// same fibre at draft quality (2026-12-06: white 274 s against 52-60, pink 201-243 against
// 47-52, metrics.json seconds.total_before_report), and the estimate says so within 2x.
TEST(VerifyPlan, EstimateOfAFeltCountsItsLongerPaths) {
  VerifyRequest r;
  r.quality = "draft";
  r.threads = 2;
  r.fiber = "white-cotton";
  const VerifyEstimate poplin = estimate_verify(plan_verify(r));
  r.weave = (fs::path(WEFT_SOURCE_DIR) / "scenes/examples/acrylic-felt.json").string();
  const VerifyEstimate felt = estimate_verify(plan_verify(r));
  EXPECT_GT(felt.typical / poplin.typical, 4.7 / 2);
  EXPECT_LT(felt.typical / poplin.typical, 5.7 * 2);
}

// A calibrated run's estimate counts its colour readings: the bundled suite's calibrated draft
// run (2026-12-06, 2 threads, a loaded machine) took 4.7-11.5 s of wall time for its colour
// match per fabric (metrics.json seconds.colour_match), against 0 without a colour.
TEST(VerifyPlan, EstimateCountsTheColourReadings) {
  VerifyRequest r;
  r.quality = "draft";
  r.threads = 2;
  const VerifyEstimate plain = estimate_verify(plan_verify(r));
  r.colour_from = "measured";
  const VerifyEstimate calibrated = estimate_verify(plan_verify(r));
  const double readings = calibrated.typical - plain.typical;
  EXPECT_GT(readings / plain.cores, 4.7 / 2);
  EXPECT_LT(readings / plain.cores, 11.5 * 2);
  EXPECT_GT(calibrated.least, plain.least);
}

}  // namespace
}  // namespace weft
