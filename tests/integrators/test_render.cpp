// Whole renders: bit-identical at any thread count, cancellation writes nothing, outputs
// round-trip.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/integrators/bench.h"
#include "weft/integrators/image.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_job.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {
SceneDescription woven() {
  WeaveParams p;
  p.yarns = 4, p.segments = 32, p.sides = 6;
  SceneDescription d = weave_bench_scene(p);
  d.lights.environment = Rgb(0.2);  // adds area-like MIS paths to the directional light
  return d;
}

RenderSettings small(int threads) {
  RenderSettings s;
  s.width = 45;  // not a multiple of the tile size
  s.height = 37;
  s.spp = 3;
  s.seed = 5;
  s.threads = threads;
  return s;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST(Render, BitIdenticalAtAnyThreadCount) {
  const SceneDescription d = woven();
  const RenderScene scene(d);
  RenderSettings s1 = small(1);
  s1.mask_meshes = d.select_object("warp");
  const RenderResult a = render(scene, *d.camera, s1);
  double total = 0;
  for (float v : a.image.rgb) total += v;
  ASSERT_GT(total, 0);
  for (int threads : {2, 0}) {  // 0 = all cores
    RenderSettings sn = s1;
    sn.threads = threads;
    const RenderResult b = render(scene, *d.camera, sn);
    ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
    EXPECT_EQ(
        0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
    EXPECT_EQ(a.masked_sum, b.masked_sum);
    EXPECT_EQ(a.coverage, b.coverage);
    EXPECT_EQ(a.rays.total(), b.rays.total());
  }
  // A different seed gives a different image (the comparison above can fail).
  RenderSettings other = s1;
  other.seed = 6;
  const RenderResult c = render(scene, *d.camera, other);
  EXPECT_NE(
      0, std::memcmp(a.image.rgb.data(), c.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
}

TEST(Render, CancellationWritesNothing) {
  const fs::path dir = fresh_dir("weft_test_cancel");
  RenderJob job;
  job.exr = dir / "out.exr";
  job.png = dir / "out.png";
  job.settings = small(2);
  int calls = 0;
  const RenderJobResult r =
      render_to_files(woven(), job, [&](const ProgressUpdate&) { return ++calls < 2; });
  EXPECT_TRUE(r.cancelled);
  EXPECT_TRUE(fs::is_empty(dir));  // no output, no temporary left behind
  fs::remove_all(dir);
}

TEST(Render, OutputsRoundTrip) {
  const fs::path dir = fresh_dir("weft_test_outputs");
  const SceneDescription d = woven();
  RenderJob job;
  job.exr = dir / "out.exr";
  job.png = dir / "out.png";
  job.mask = dir / "mask.exr";
  job.mask_object = "weft";
  job.settings = small(2);
  const RenderJobResult r = render_to_files(d, job);
  ASSERT_FALSE(r.cancelled);
  const RenderResult direct = render(RenderScene(d), *d.camera, small(1));
  const Image back = read_image(job.exr);
  ASSERT_EQ(back.width, 45);
  ASSERT_EQ(back.height, 37);
  EXPECT_EQ(back.rgb, direct.image.rgb);
  EXPECT_GT(fs::file_size(*job.png), 0u);
  EXPECT_GT(fs::file_size(*job.mask), 0u);
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 3);
  fs::remove_all(dir);
}

TEST(Render, BadOutputsFailBeforeRendering) {
  const fs::path dir = fresh_dir("weft_test_badout");
  RenderJob job;
  job.settings = small(1);
  job.exr = dir / "out.png";
  EXPECT_THROW(render_to_files(woven(), job), Error);
  job.exr = dir / "missing" / "out.exr";
  EXPECT_THROW(render_to_files(woven(), job), Error);
  job.exr = dir / "out.exr";
  job.mask = dir / "mask.exr";
  job.mask_object = "no such object";
  EXPECT_THROW(render_to_files(woven(), job), Error);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}
