// The fiber count of a yarn section when the user gives neither --packing nor --fibers-per-yarn
// (weave.h): the default packing where it fits, else the densest packing the section admits,
// said in the summary's notes; a value the user gives that does not fit stays an error naming it.
// And every bundled WIF draft weaves at fiber detail with the defaults.
#include <gtest/gtest.h>

#include <filesystem>

#include "lambert_scene.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/scenes/weave.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {

using weft::testing::kWifDir;

// The bundled 2 x 2 plain draft at fiber detail, nothing else given: its threads (0.185 mm
// spacing, scenes/data/wif/README.md) are narrower than red cotton's, so the default packing
// 0.55 does not fit them.
WeaveOptions small_draft() {
  WeaveOptions o;
  o.wif = (kWifDir / "54235-plain.wif").string();
  o.detail = "fiber";
  return o;
}

using weft::testing::woven_sample_error;

}  // namespace

TEST(Packing, SectionThatFitsOnlyLessTakesTheDensestThatFits) {
  const WovenSample s = make_woven_sample(small_draft());
  ASSERT_EQ(s.summary.warp_fibers.size(), 1u);
  const FiberLayoutInfo warp = s.summary.warp_fibers[0];
  EXPECT_EQ(warp.default_packing, 0.55);  // red cotton's, weave.h
  EXPECT_LT(warp.packing, 0.55);
  EXPECT_GT(warp.fibers, 1);
  ASSERT_FALSE(s.summary.notes.empty());
  EXPECT_NE(s.summary.notes[0].find("densest packing that fits"), std::string::npos);
  // Densest: the count taken, given explicitly, makes the same fibers; one more does not fit,
  // and the error names the field the user gave.
  WeaveOptions o = small_draft();
  o.fibers_per_yarn = warp.fibers;
  const WovenSample same = make_woven_sample(o);
  EXPECT_EQ(same.fibers.points, s.fibers.points);
  EXPECT_TRUE(same.summary.notes.empty());
  o.fibers_per_yarn = warp.fibers + 1;
  const std::string e = woven_sample_error(o);
  EXPECT_NE(e.find("field 'fibers-per-yarn'"), std::string::npos) << e;
  EXPECT_NE(e.find("at most " + std::to_string(warp.fibers) + " fibers"), std::string::npos) << e;
}

TEST(Packing, ExplicitPackingThatDoesNotFitIsAnError) {
  WeaveOptions o = small_draft();
  o.packing = 0.55;  // the default, but given
  const std::string e = woven_sample_error(o);
  EXPECT_NE(e.find("field 'packing'"), std::string::npos) << e;
  EXPECT_NE(e.find("at most"), std::string::npos) << e;
}

TEST(Packing, DefaultPackingIsKeptWhereItFits) {
  // The red-cotton poplin holds the default packing: leaving it out changes nothing.
  WeaveOptions given = red_cotton_weave_options();
  given.detail = "fiber";
  WeaveOptions unset = given;
  unset.packing.reset();
  const WovenSample a = make_woven_sample(given), b = make_woven_sample(unset);
  EXPECT_EQ(a.fibers.points, b.fibers.points);
  EXPECT_TRUE(b.summary.notes.empty());
  for (const auto& f : b.summary.warp_fibers) EXPECT_EQ(f.default_packing, 0);
}

TEST(Packing, EveryBundledWifWeavesAtFiberDetail) {
  int drafts = 0;
  for (const auto& entry : fs::directory_iterator(kWifDir)) {
    if (entry.path().extension() != ".wif") continue;
    WeaveOptions o;
    o.wif = entry.path().string();
    o.detail = "fiber";
    const WovenSample s = make_woven_sample(o);
    EXPECT_GT(s.summary.curves, 0u) << *o.wif;
    // The generator's own measurement: fibers keep two radii (red cotton's 8 um) apart.
    EXPECT_GE(s.summary.min_fiber_distance_um, 16 * (1 - 1e-2)) << *o.wif;
    ++drafts;
  }
  EXPECT_GE(drafts, 2);  // 54235-plain.wif, 8452.wif (scenes/data/wif/README.md)
}
