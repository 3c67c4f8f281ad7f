#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "../test_util.h"
#include "weft/core/colorimetry.h"
#include "weft/fabric/fabric_colour.h"

using namespace weft;
using namespace weft::testing;

namespace {

// The bake cache is ./.weft-cache: each test works in a folder of its own.
struct InFolder {
  std::filesystem::path before = std::filesystem::current_path();
  explicit InFolder(const std::filesystem::path& dir) { std::filesystem::current_path(dir); }
  ~InFolder() { std::filesystem::current_path(before); }
};

FabricBakeRequest small_trace(const std::string& colour) {
  FabricBakeRequest r;
  r.fiber = "red-cotton";
  r.method = "raytrace";
  r.resolution = 2;
  r.samples = 3000;
  r.colour = colour;
  return r;
}

}  // namespace

TEST(FabricColour, PlanRefusesWhatItCannotDye) {
  const auto dir = fresh_test_dir();
  write_file(dir / "fiber.exr", "not read");
  FabricBakeRequest r = small_trace("lab:40,20,10");
  r.fiber = (dir / "fiber.exr").string();
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("a baked fiber table's colour is fixed"),
            std::string::npos);
  r = small_trace("lab:40,20,10");
  r.warp_fiber = "white-cotton";
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("per-yarn fibers"), std::string::npos);
  r = small_trace("lab:400,20,10");
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("field '--colour'"), std::string::npos);
}

TEST(FabricColour, TheMatchedTableReadsTheTargetAndTheMatchIsCached) {
  const auto dir = fresh_test_dir();
  InFolder in(dir);
  // A target the recipe as written meets: the reading of the red-cotton poplin itself.
  const FabricBakePlan probe = plan_fabric_bake(small_trace("lab:50,0,0"));
  const WovenSample sample = make_woven_sample(probe.weave);
  const std::optional<Spectrum> r =
      fabric_d8_reading(probe, sample, load_fiber_spec("red-cotton"), no_progress());
  ASSERT_TRUE(r);
  const Lab lab = reflectance_to_lab(*r, Observer::kCie1931TwoDegree);
  char spec[96];
  std::snprintf(spec, sizeof spec, "lab:%.5f,%.5f,%.5f", lab.l, lab.a, lab.b);

  const FabricBakeResult first = run_fabric_bake(plan_fabric_bake(small_trace(spec)), {});
  const nlohmann::json& m = first.summary.at("colour_match");
  EXPECT_EQ(m.at("reached"), true);
  EXPECT_EQ(m.at("iterations"), 1);  // the recipe as written is on target: no other reading
  EXPECT_EQ(m.at("cached"), false);
  EXPECT_LT(m.at("delta_e00").get<double>(), 1e-3);
  // The whole table's normal row is the reading's bit for bit (same seed, same bin).
  EXPECT_EQ(m.at("table").at("channels"), "spectral");
  EXPECT_LT(m.at("table").at("delta_e00").get<double>(), 1e-3);
  EXPECT_EQ(first.table.channels, kNumBands);
  EXPECT_NE(first.table.metadata.at("colour").find(spec), std::string::npos);

  const FabricBakeResult second = run_fabric_bake(plan_fabric_bake(small_trace(spec)), {});
  EXPECT_EQ(second.summary.at("colour_match").at("cached"), true);
  EXPECT_EQ(second.table.checksum(), first.table.checksum());
}
