// Whole renders: bit-identical at any thread count, cancellation writes nothing, outputs
// round-trip.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/integrators/image.h"
#include "weft/integrators/masked_render.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_job.h"
#include "weft/scenes/render_scene.h"
#include "woven_patch.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {
using weft::testing::lit_woven_patch;
using weft::testing::small_render_settings;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST(Render, BitIdenticalAtAnyThreadCount) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  const std::vector<uint8_t> mask = d.select_object("warp");
  const MaskedRender a = render_masked(scene, *d.camera, small_render_settings(1), mask);
  double total = 0;
  for (float v : a.render.image.rgb) total += v;
  ASSERT_GT(total, 0);
  for (int threads : {2, 0}) {  // 0 = all cores
    const MaskedRender b = render_masked(scene, *d.camera, small_render_settings(threads), mask);
    const auto &ia = a.render.image.rgb, &ib = b.render.image.rgb;
    ASSERT_EQ(ia.size(), ib.size());
    EXPECT_EQ(0, std::memcmp(ia.data(), ib.data(), ia.size() * sizeof(float)));
    EXPECT_EQ(a.sum, b.sum);
    EXPECT_EQ(a.coverage, b.coverage);
    EXPECT_EQ(a.render.rays.total(), b.render.rays.total());
  }
  // The mask only observes: the image is render()'s.
  const RenderResult plain = render(scene, *d.camera, small_render_settings(2));
  EXPECT_EQ(plain.image.rgb, a.render.image.rgb);
  // A different seed gives a different image (the comparison above can fail).
  RenderSettings other = small_render_settings(1);
  other.seed = 6;
  const RenderResult c = render(scene, *d.camera, other);
  EXPECT_NE(0, std::memcmp(a.render.image.rgb.data(), c.image.rgb.data(),
                           a.render.image.rgb.size() * sizeof(float)));
}

// A render traces a pixel's camera rays, and their first shadow rays, together (packets of
// RenderScene::kPacketRays); each pixel is still, bit for bit, the mean of its samples' paths
// traced one by one (trace_path), each from its own stream. 19 samples: a full packet and a
// part of one; five point lights besides the parallel light and the environment: more light
// samples at a vertex than a path holds for a packet (PathTrace::kHeldShadows).
TEST(Render, PixelsAreTheirPathsTracedOneByOne) {
  SceneDescription d = lit_woven_patch();
  for (int k = 0; k < 5; ++k)
    d.lights.points.push_back({Vec3{0.004 * (k - 2), 0.01, 0.003 * (k % 2)}, Rgb(1e-5 * (k + 1))});
  const RenderScene scene(d);
  RenderSettings s = small_render_settings(2);
  s.width = 11, s.height = 9, s.spp = 19;
  const RenderResult r = render(scene, *d.camera, s);
  const double aspect = double(s.width) / s.height;
  double total = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const uint64_t pixel = uint64_t(y) * s.width + x;
      double sum[3] = {0, 0, 0};
      for (int k = 0; k < s.spp; ++k) {
        Rng rng(s.seed, pixel, uint64_t(k));
        const double fx = (x + rng.uniform()) / s.width, fy = (y + rng.uniform()) / s.height;
        RayCounts rays;
        const Rgb L = trace_path(scene, d.camera->generate_ray(fx, fy, aspect), s, rng, rays);
        sum[0] += L.r, sum[1] += L.g, sum[2] += L.b;
      }
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(r.image.rgb[3 * pixel + c], static_cast<float>(sum[c] * (1.0 / s.spp)))
            << "pixel " << x << ", " << y << " channel " << c;
        total += sum[c];
      }
    }
  EXPECT_GT(total, 0);
}

// With the packets off (RenderScene::with_ray_packets, the bench's comparison) every query goes
// one by one and the image keeps its bits; the switch survives a change of lights.
TEST(Render, RayPacketsOffGiveTheSameImage) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  const RenderScene single = scene.with_ray_packets(false);
  EXPECT_FALSE(single.ray_packets());
  EXPECT_FALSE(single.with_lights(d.lights).ray_packets());
  EXPECT_EQ(scene.with_ray_packets(true).ray_packets(), scene.ray_packets());
  const RenderResult a = render(scene, *d.camera, small_render_settings(2));
  const RenderResult b = render(single, *d.camera, small_render_settings(2));
  double total = 0;
  for (float v : a.image.rgb) total += v;
  EXPECT_GT(total, 0);
  ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
  EXPECT_EQ(
      0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  EXPECT_EQ(a.rays.total(), b.rays.total());
}

TEST(Render, ObserversSeeEverySampleAndRay) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  const RenderSettings s = small_render_settings(2);
  std::vector<uint32_t> samples(size_t(s.width) * s.height, 0);
  std::vector<double> sums(3 * samples.size(), 0.0);
  std::atomic<uint64_t> rays{0}, shadow_rays{0};
  RenderObservers observers;
  observers.on_sample = [&](uint64_t pixel, int64_t first_mesh, const Rgb& L) {
    ASSERT_LT(pixel, samples.size());
    ASSERT_GE(first_mesh, -1);
    ASSERT_LT(first_mesh, int64_t(scene.mesh_count()));
    ++samples[pixel];
    sums[3 * pixel] += L.r, sums[3 * pixel + 1] += L.g, sums[3 * pixel + 2] += L.b;
  };
  observers.on_ray = [&](const Ray&, bool shadow) {
    ++rays;
    if (shadow) ++shadow_rays;
  };
  const RenderResult r = render(scene, *d.camera, s, no_progress(), observers);
  for (size_t p = 0; p < samples.size(); ++p) {
    ASSERT_EQ(samples[p], uint32_t(s.spp));
    // The pixel is the mean of the samples it was shown.
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(r.image.rgb[3 * p + c], static_cast<float>(sums[3 * p + c] * (1.0 / s.spp)));
  }
  EXPECT_EQ(shadow_rays.load(), r.rays.shadow);
  // Every camera ray is traced; RayCounts::bounce also counts the bounces that Russian roulette
  // ends before they are traced.
  const uint64_t traced = rays.load() - shadow_rays.load();
  EXPECT_GE(traced, r.rays.camera);
  EXPECT_LE(traced, r.rays.camera + r.rays.bounce);
  EXPECT_GT(traced, r.rays.camera);  // some paths bounce
}

TEST(Render, CancellationWritesNothing) {
  const fs::path dir = fresh_dir("weft_test_cancel");
  RenderJob job;
  job.exr = dir / "out.exr";
  job.png = dir / "out.png";
  job.settings = small_render_settings(2);
  int calls = 0;
  const RenderJobResult r =
      render_to_files(lit_woven_patch(), job, [&](const ProgressUpdate&) { return ++calls < 2; });
  EXPECT_TRUE(r.cancelled);
  EXPECT_TRUE(fs::is_empty(dir));  // no output, no temporary left behind
  fs::remove_all(dir);
}

TEST(Render, OutputsRoundTrip) {
  const fs::path dir = fresh_dir("weft_test_outputs");
  const SceneDescription d = lit_woven_patch();
  RenderJob job;
  job.exr = dir / "out.exr";
  job.png = dir / "out.png";
  job.mask = dir / "mask.exr";
  job.mask_object = "weft";
  job.settings = small_render_settings(2);
  const RenderJobResult r = render_to_files(d, job);
  ASSERT_FALSE(r.cancelled);
  const RenderResult direct = render(RenderScene(d), *d.camera, small_render_settings(1));
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
  job.settings = small_render_settings(1);
  job.exr = dir / "out.tif";  // .exr, .png or .hdr only
  EXPECT_THROW(render_to_files(lit_woven_patch(), job), Error);
  job.exr = dir / "missing" / "out.exr";
  EXPECT_THROW(render_to_files(lit_woven_patch(), job), Error);
  job.exr = dir / "out.exr";
  job.mask = dir / "mask.exr";
  job.mask_object = "no such object";
  EXPECT_THROW(render_to_files(lit_woven_patch(), job), Error);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}
