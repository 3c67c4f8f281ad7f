// plan_fabric_bake (fabric_bake.h): the sample's options the plan settles on before any work.
#include <gtest/gtest.h>

#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fabric/fabric_bake.h"

using namespace weft;
using namespace weft::testing;

namespace {

FabricBakeRequest felt_trace() {
  FabricBakeRequest r;
  r.fiber = "acrylic";
  r.method = "raytrace";
  r.weave = (std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/examples/acrylic-felt.json").string();
  r.resolution = 1;
  r.samples = 1;
  r.output = (fresh_test_dir() / "felt.exr").string();
  return r;
}

}  // namespace

// A weave file's "detail" is what the user named: a bake without --detail keeps it (the felt's
// file says fiber, its only detail; the bake's own default of yarn once replaced it and the felt
// was refused for a detail nobody gave). --detail, when given, is put over it.
TEST(FabricBakePlan, TheSampleFilesDetailHoldsUnlessDetailIsGiven) {
  FabricBakeRequest r = felt_trace();
  EXPECT_EQ(plan_fabric_bake(r).weave.detail.value_or(""), "fiber");
  r.detail = "yarn";
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("fiber detail only"), std::string::npos);
  r = felt_trace();
  r.weave.clear();  // the bundled poplin: yarn detail unless given
  EXPECT_EQ(plan_fabric_bake(r).weave.detail.value_or("yarn"), "yarn");
  r.detail = "fiber";
  EXPECT_EQ(plan_fabric_bake(r).weave.detail.value_or(""), "fiber");
}
