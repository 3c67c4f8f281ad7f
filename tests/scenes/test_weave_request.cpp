// weft weave's request and plan (weave_request.h): the legacy patch's options alone, sizes for
// both directions or per direction, one of each pair of alternatives, the options over the
// sample description's.
#include <gtest/gtest.h>

#include "test_util.h"
#include "weft/scenes/weave_request.h"

using namespace weft;
using weft::testing::error_of;
using weft::testing::kExamples;

TEST(WeaveRequest, LegacyOptionsRefuseTheSamplesAndKeepPatternAndSides) {
  WeaveRequest q;
  q.output = "legacy.glb";
  q.yarns = 4;
  q.options.detail = "fiber";
  EXPECT_EQ(error_of([&] { plan_weave(q); }),
            "field 'detail': cannot be combined with the legacy open-mesh options (--yarns, "
            "--yarn-radius-mm, --spacing-mm, --segments, --amplitude-mm)");
  q.options.detail.reset();
  q.options.pattern = "twill:2/1";
  q.options.sides = 5;
  const WeavePlan p = plan_weave(q);
  ASSERT_TRUE(p.legacy);
  EXPECT_EQ(p.legacy->yarns, 4);
  EXPECT_EQ(p.legacy->pattern, "twill:2/1");
  EXPECT_EQ(p.legacy->sides, 5);
  EXPECT_EQ(p.legacy->spacing_mm, WeaveParams{}.spacing_mm);
}

TEST(WeaveRequest, YarnSizeSetsBothDirectionsUnlessOneIsGiven) {
  WeaveRequest q;
  q.output = "w.glb";
  q.yarn_width_mm = 0.2;
  const WeavePlan p = plan_weave(q);
  EXPECT_FALSE(p.legacy);
  EXPECT_EQ(p.options.warp_width_mm, 0.2);
  EXPECT_EQ(p.options.weft_width_mm, 0.2);
  q.options.weft_width_mm = 0.3;
  EXPECT_NE(error_of([&] { plan_weave(q); }).find("field 'yarn-width-mm'"), std::string::npos);
}

TEST(WeaveRequest, PairsOfAlternativesAndRepeats) {
  WeaveRequest q;
  q.output = "w.glb";
  q.options.packing = 0.5;
  q.options.fibers_per_yarn = 20;
  EXPECT_EQ(error_of([&] { plan_weave(q); }),
            "field 'packing': give either --packing or --fibers-per-yarn, not both");
  q.options.packing.reset();
  q.repeats = "2x";
  EXPECT_NE(error_of([&] { plan_weave(q); }).find("field 'repeats'"), std::string::npos);
  q.repeats = "2x3";
  const WeavePlan p = plan_weave(q);
  EXPECT_EQ(p.options.repeats_x, 2);
  EXPECT_EQ(p.options.repeats_z, 3);
}

TEST(WeaveRequest, GivenOptionsOverTheSampleDescriptions) {
  WeaveRequest q;
  q.output = "w.glb";
  q.sample = (kExamples / "polyester-twill-weave.json").string();
  q.options.pattern = "plain";
  const WeavePlan p = plan_weave(q);
  EXPECT_EQ(p.options.pattern, "plain");
  EXPECT_EQ(p.options.fiber_radius_um, read_weave_options(*q.sample).fiber_radius_um);
}
