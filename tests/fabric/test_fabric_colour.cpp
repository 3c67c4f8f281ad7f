#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "../test_util.h"
#include "weft/core/colorimetry.h"
#include "weft/fabric/fabric_colour.h"
#include "weft/fabric/fiber_colour.h"
#include "weft/fiber/thread_colour.h"
#include "weft/materials/colour_reading.h"

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

// `weft bake fiber --colour` (fabric/fiber_colour.h): what it cannot match is refused before any
// work, and the fiber library alone never drops a colour without a word.
TEST(FiberColour, PlanRefusesWhatItCannotMatch) {
  FiberBakeRequest r;
  r.spec = "red-cotton";
  r.option_prefix = "--";
  r.colour_weave = "weave.json";
  EXPECT_NE(error_of([&] { plan_coloured_fiber_bake(r); }).find("field '--colour-weave'"),
            std::string::npos);
  r.colour_weave.clear();
  r.colour = "lab:40,20,10";
  EXPECT_NE(error_of([&] { plan_fiber_bake(r); }).find("field '--colour'"), std::string::npos);
  r.shard = "1/2";
  EXPECT_NE(error_of([&] { plan_coloured_fiber_bake(r); }).find("sharded or resumed"),
            std::string::npos);
  r.shard.clear();
  r.spec_read = load_fiber_spec("red-cotton");
  EXPECT_NE(error_of([&] { plan_coloured_fiber_bake(r); }).find("give the spec as a file"),
            std::string::npos);
  r.spec_read.reset();
  r.colour = "lab:400,20,10";
  EXPECT_NE(error_of([&] { plan_coloured_fiber_bake(r); }).find("field '--colour'"),
            std::string::npos);
  // Without a colour it is the plain bake's plan.
  r.colour.clear();
  EXPECT_FALSE(plan_coloured_fiber_bake(r).reading);
}

// The fiber's colour is read through a cloth: a target that the recipe as written meets (the
// cloth's own reading) takes one reading, the table says how near in its metadata, and the match
// is cached by its inputs.
TEST(FiberColour, TheRecipeOnTargetTakesOneReadingAndIsCached) {
  const auto dir = fresh_test_dir();
  InFolder in(dir);
  FiberBakeRequest r;
  r.spec = "red-cotton";
  r.photons = 2000;
  r.resolution = 4;
  r.colour = "lab:50,0,0";
  const ColouredFiberBakePlan probe = plan_coloured_fiber_bake(r);
  ASSERT_TRUE(probe.reading);
  EXPECT_EQ(probe.reading->method, FabricMethod::kRaytrace);
  const WovenSample sample = make_woven_sample(probe.reading->weave);
  const std::optional<Spectrum> reading =
      fabric_d8_reading(*probe.reading, sample, load_fiber_spec("red-cotton"), no_progress());
  ASSERT_TRUE(reading);
  const Lab lab = reflectance_to_lab(*reading, Observer::kCie1931TwoDegree);
  char spec[96];
  std::snprintf(spec, sizeof spec, "lab:%.5f,%.5f,%.5f", lab.l, lab.a, lab.b);
  r.colour = spec;

  const FiberBakeOutcome first = run_coloured_fiber_bake(plan_coloured_fiber_bake(r));
  ASSERT_TRUE(first.table);
  const nlohmann::json& m = first.summary.at("colour_match");
  EXPECT_EQ(m.at("reached"), true);
  EXPECT_EQ(m.at("iterations"), 1);
  EXPECT_EQ(m.at("cached"), false);
  EXPECT_LT(m.at("delta_e00").get<double>(), 1e-3);
  EXPECT_NE(first.table->table.metadata.at("colour").find(spec), std::string::npos);
  EXPECT_EQ(first.table->table.resolution, 4);  // the request's own settings, not the reading's

  const FiberBakeOutcome second = run_coloured_fiber_bake(plan_coloured_fiber_bake(r));
  EXPECT_EQ(second.summary.at("colour_match").at("cached"), true);
  EXPECT_EQ(second.table->table.checksum(), first.table->table.checksum());
}

// --thread-colours match: each thread colour's absorbers are solved through a cloth of that thread
// alone, so the cloth comes nearer the draft's swatch than the rule's one-pass uplift, which makes
// it darker and more saturated (fiber/thread_colour.h); white stays the undyed fibre.
TEST(FabricColour, MatchedThreadColoursComeNearerTheSwatchThanTheRule) {
  const auto dir = fresh_test_dir();
  InFolder in(dir);
  FabricBakeRequest r;
  r.fiber = "white-cotton";
  r.method = "raytrace";
  r.detail = "yarn";
  r.resolution = 2;
  r.samples = 2000;
  r.wif = (std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/data/wif/red-white-twill.wif").string();
  r.thread_colours = true;
  const FabricBakePlan plan = plan_fabric_bake(r);
  EXPECT_EQ(plan.fibers.thread_colour_method, ThreadColourMethod::kMatch);
  const WovenSample sample = make_woven_sample(plan.weave);
  nlohmann::json summary;
  const auto specs = match_thread_colours(plan, sample, no_progress(), summary);
  ASSERT_TRUE(specs);
  // [COLOR TABLE] 1 = 200,30,30 (warps), 2 = 255,255,255 (wefts), warps first.
  ASSERT_EQ(specs->size(), 2u);
  EXPECT_EQ(summary[0].at("colour"), "#c81e1e");
  EXPECT_EQ((*specs)[1].name, "white-cotton");
  const double matched = summary[0].at("delta_e00").get<double>();
  const std::array<double, 3> red{200 / 255.0, 30 / 255.0, 30 / 255.0};
  const ColourTarget target = read_colour_target("srgb:#c81e1e", "test");
  const FiberSpec base = load_fiber_spec("white-cotton");
  const std::optional<Spectrum> rule =
      fabric_d8_reading(plan, sample, thread_colour_spec(base, red, "test"), no_progress());
  ASSERT_TRUE(rule);
  const double by_rule = delta_e00(target.lab, target.lab_of(*rule));
  EXPECT_LT(matched, by_rule) << "rule " << by_rule;
  std::printf(
      "#c81e1e on the red/white twill: CIEDE2000 %.2f matched (%d readings), %.2f by rule\n",
      matched, summary[0].at("iterations").get<int>(), by_rule);
  // Refused before any work: a dyed --fiber (its own dyes would fight the match), and the
  // method without --thread-colours.
  r.fiber = "red-cotton";
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("--thread-colour-method"),
            std::string::npos);
  r.fiber = "white-cotton";
  r.thread_colours = false;
  r.thread_colour_method = "rule";
  EXPECT_NE(error_of([&] { plan_fabric_bake(r); }).find("give --thread-colours"),
            std::string::npos);
}
