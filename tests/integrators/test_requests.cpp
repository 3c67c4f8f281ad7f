// weft render's and weft sweep's requests and plans (render_request.h, sweep_request.h): the rules
// a plan checks before any work, the settings it puts over the scene's, and a sharded sweep whose
// merged parts are the whole sweep's table.
#include <gtest/gtest.h>

#include <filesystem>

#include "test_util.h"
#include "weft/integrators/render_request.h"
#include "weft/integrators/sweep_request.h"

using namespace weft;
using weft::testing::error_of;
using weft::testing::kExamples;

namespace {

RenderRequest plane_render(const std::filesystem::path& dir) {
  RenderRequest q;
  q.scene = (kExamples / "lambert-plane.json").string();
  q.output = (dir / "plane.exr").string();
  return q;
}

SweepRequest plane_sweep(const std::filesystem::path& dir) {
  SweepRequest q;
  q.scene = (kExamples / "lambert-plane.json").string();
  q.output = (dir / "sweep.csv").string();
  q.light_zenith_deg = 30;
  q.view_zenith_deg = "-60:60:30";
  q.spp = 1;
  q.resolution = 8;
  return q;
}

}  // namespace

TEST(RenderRequest, PlanChecksTheMaskObjectBeforeTheScene) {
  RenderRequest q;
  q.scene = "no-such-scene.json";
  q.mask = "mask.exr";
  EXPECT_NE(error_of([&] { plan_render(q); }).find("--mask-object"), std::string::npos);
}

TEST(RenderRequest, PlanPutsTheRequestOverTheScenesSettings) {
  const auto dir = weft::testing::fresh_test_dir();
  RenderRequest q = plane_render(dir);
  q.spp = 3, q.width = 40, q.height = 20, q.seed = 7;
  q.aov = "normal,albedo";
  q.crop = "1,5,2,6";
  q.exposure_ev = 1;
  int loaded = 0;
  ScenePlanHooks hooks;
  hooks.scene_loaded = [&](const SceneDescription&) { ++loaded; };
  const RenderPlan p = plan_render(q, hooks);
  EXPECT_EQ(loaded, 1);
  EXPECT_EQ(p.job.settings.spp, 3);
  EXPECT_EQ(p.job.settings.width, 40);
  EXPECT_EQ(p.job.settings.height, 20);
  EXPECT_EQ(p.job.settings.seed, 7u);
  ASSERT_TRUE(p.job.settings.crop);
  EXPECT_EQ(p.job.settings.crop->x1, 5);
  EXPECT_EQ(p.job.preview_exposure, 2);
  EXPECT_EQ(p.job.albedo, dir / "plane.albedo.exr");
  EXPECT_EQ(p.job.normal, dir / "plane.normal.exr");
  EXPECT_FALSE(p.inputs.empty());
}

TEST(RenderRequest, PlanRefusesUnknownPassesBadCropsAndTheSceneAsOutput) {
  const auto dir = weft::testing::fresh_test_dir();
  RenderRequest q = plane_render(dir);
  q.aov = "albedo,depth";
  EXPECT_NE(error_of([&] { plan_render(q); }).find("unknown pass 'depth'"), std::string::npos);
  q = plane_render(dir);
  q.crop = "0,1,2";
  EXPECT_NE(error_of([&] { plan_render(q); }).find("--crop"), std::string::npos);
  q = plane_render(dir);
  q.preview = q.scene;
  EXPECT_NE(error_of([&] { plan_render(q); }).find("--preview"), std::string::npos);
}

TEST(SweepRequest, PlanChecksTheNormalizationAndTheShard) {
  const auto dir = weft::testing::fresh_test_dir();
  SweepRequest q = plane_sweep(dir);
  q.normalize_to = "1,2";
  EXPECT_NE(error_of([&] { plan_sweep(q); }).find("needs 1 or 3 values"), std::string::npos);
  q.normalize_to = "0.5";
  q.shard = "2/2";
  EXPECT_NE(error_of([&] { plan_sweep(q); }).find("--shard"), std::string::npos);
  q.shard = "1/2";
  const SweepPlan p = plan_sweep(q);
  EXPECT_TRUE(p.partial);
  ASSERT_TRUE(p.settings.units);
  EXPECT_EQ(*p.settings.units, p.todo);
  EXPECT_EQ(p.todo.front(), p.range.first);
  EXPECT_EQ(p.settings.view_zenith_deg.size(), 5u);
}

TEST(SweepRequest, MergedShardsAreTheWholeSweep) {
  const auto dir = weft::testing::fresh_test_dir();
  SweepRequest whole = plane_sweep(dir);
  whole.normalize_to = "0.5";
  const SweepOutcome w = run_sweep(plan_sweep(whole));
  ASSERT_TRUE(w.table);
  EXPECT_EQ(w.table->rows.size(), 5u);
  std::vector<std::filesystem::path> parts;
  for (const char* shard : {"0/2", "1/2"}) {
    SweepRequest q = whole;
    q.shard = shard;
    q.output = (dir / (std::string("part") + shard[0])).string();
    const SweepOutcome s = run_sweep(plan_sweep(q));
    EXPECT_FALSE(s.table);
    parts.push_back(q.output);
  }
  const GonioResult merged = merge_sweep_parts(merge_job_parts(parts), dir / "merged.csv");
  EXPECT_EQ(merged.rows.size(), 5u);
  EXPECT_EQ(weft::testing::slurp(dir / "merged.csv"), weft::testing::slurp(whole.output));
}
