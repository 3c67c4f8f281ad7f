// The weave level of a fabric_table (weave_modulation.h, weave_level.h) against its table level.
// A flat patch (UVs in metres, tangents along u) carries a fabric table and a weave table whose
// modulation is a strong two-colour checker (R 1.8 / 0.2, G 0.2 / 1.8, B 1) over 4 x 4 cells of a
// 1 cm repeat. The checker's mean over the repeat is 1 in every channel by construction, and the
// renderer's bilinear blend of the cells keeps that mean (each cell's tent integrates to one cell),
// so over whole repeats the weave level has the table level's mean radiance: the reference of
// every comparison below. Noise: each comparison's tolerance is 4 standard errors of the image
// means (from the pixels' spread), and the same means from a second seed are printed beside it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/weave_level.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_table.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

constexpr double kRepeat_m = 0.01;  // the weave's repeat, 1 cm
constexpr double kHalfFov = 0.05;   // tan(yfov / 2): the film spans 0.1 x the distance
constexpr double kFar_m = 10;       // film 1 m = 100 repeats: 0.64 px a repeat at 64 px
constexpr double kClose_m = 0.2;    // film 2 cm = 2 repeats: 32 px a repeat
constexpr int kPixels = 64;

// A transmitting Lambert-like fabric table: 0.5 / pi reflected, 0.3 / pi transmitted, in RGB or
// in 33 bands.
fs::path write_fabric_table(const fs::path& dir, int channels = 3) {
  auto t = TabulatedBsdfTable::from_function(
      4, channels,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        for (double& x : v) x = (wo.z * wi.z > 0 ? 0.5 : 0.3) / kPi;
      },
      2, 1);
  t.kind = "fabric";
  const fs::path file = dir / ("fabric" + std::to_string(channels) + ".exr");
  t.write_exr(file);
  return file;
}

// The checker weave: cell (iu, iv) is colour A when iu + iv is even, else B; mean 1 exactly
// (8 cells of each). In bands: the first 11 bands as R above, the next 11 as G, the rest 1.
fs::path write_checker_weave(const fs::path& dir, int channels = 3) {
  WeaveTable w;
  w.channels = channels;
  w.resolution = 2;
  w.positions_u = w.positions_v = 4;
  w.repeat_u_m = w.repeat_v_m = kRepeat_m;
  const int n = w.bins();
  w.modulation.resize(static_cast<size_t>(w.positions()) * n * n * channels);
  for (int iv = 0; iv < 4; ++iv)
    for (int iu = 0; iu < 4; ++iu) {
      const bool a = (iu + iv) % 2 == 0;
      for (int i = 0; i < n; ++i)
        for (int o = 0; o < n; ++o) {
          const int pos = iv * 4 + iu;
          for (int c = 0; c < channels; ++c) {
            const int group = channels == 3 ? c : c / 11;
            w.modulation[w.index(pos, i, o, c)] = group == 0   ? (a ? 1.8f : 0.2f)
                                                  : group == 1 ? (a ? 0.2f : 1.8f)
                                                               : 1.0f;
          }
        }
    }
  const fs::path file = dir / ("weave" + std::to_string(channels) + ".exr");
  w.write_exr(file);
  return file;
}

// The patch: 2 m x 2 m in z = 0 around the origin, normal +z, tangent +x, uv = (x, y) metres.
std::shared_ptr<const TriangleMesh> patch() {
  auto m = std::make_shared<TriangleMesh>();
  m->material = "cloth";
  m->names = {"patch"};
  m->positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  m->normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  m->tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  m->uvs = {-1, -1, 1, -1, 1, 1, -1, 1};
  m->indices = {0, 1, 2, 0, 2, 3};
  return m;
}

struct Files {
  fs::path fabric, weave;
};

// The patch seen straight on from 'distance_m' on +z, lit by a parallel light from 30 degrees in
// front (or behind: through the cloth) and a dim environment (which adds noise to both levels).
SceneDescription patch_scene(const Files& f, const std::string& level, double distance_m,
                             bool from_behind) {
  SceneDescription d;
  d.source = "weave-level-test";
  d.meshes = {patch()};
  nlohmann::json params = {{"file", f.fabric.string()}, {"weave", f.weave.string()}};
  if (!level.empty()) params["level"] = level;
  d.materials["cloth"] = {"fabric_table", params, {}, {}, "materials.cloth"};
  const double s = std::sin(deg_to_rad(30)), c = std::cos(deg_to_rad(30));
  d.lights.directional.push_back({Vec3{s, 0, from_behind ? -c : c}, Rgb(1.0)});
  d.lights.environment = Rgb(0.1);
  Camera cam = Camera::look_at(Camera::Type::perspective, {0, 0, distance_m}, {0, 0, 0}, {0, 1, 0});
  cam.yfov_rad = 2 * std::atan(kHalfFov);
  d.camera = cam;
  return d;
}

RenderSettings settings(uint64_t seed, bool spectral = false) {
  RenderSettings s;
  s.spectral = spectral;
  s.width = s.height = kPixels;
  s.spp = 16;
  s.max_depth = 4;
  s.seed = seed;
  return s;
}

// Mean of one channel over the image, with the standard error from the pixels' spread.
SampleMean channel_mean(const Image& im, int c) {
  return sample_mean(im.width * im.height, [&](int i) { return double(im.rgb[3 * i + c]); });
}

struct Render {
  RenderResult result;
  SampleMean mean[3];
};
Render render_patch(const SceneDescription& d, uint64_t seed, bool spectral = false) {
  Render r{render(RenderScene(d), *d.camera, settings(seed, spectral)), {}};
  for (int c = 0; c < 3; ++c) r.mean[c] = channel_mean(r.result.image, c);
  return r;
}

// Same mean within 4 standard errors, channel by channel; prints the figures and the same
// comparison from a second seed (the noise seen, not only estimated).
void expect_same_means(const SceneDescription& weave, const SceneDescription& table,
                       const char* what, bool spectral = false) {
  for (uint64_t seed : {1u, 2u}) {
    const Render w = render_patch(weave, seed, spectral), t = render_patch(table, seed, spectral);
    for (int c = 0; c < 3; ++c) {
      const double se = std::hypot(w.mean[c].std_error, t.mean[c].std_error);
      std::printf("%s seed %d channel %d: weave %.6f table %.6f (diff %+.2e, 1 se %.2e)\n", what,
                  int(seed), c, w.mean[c].mean, t.mean[c].mean, w.mean[c].mean - t.mean[c].mean,
                  se);
      EXPECT_GT(t.mean[c].mean, 0) << what;
      EXPECT_NEAR(w.mean[c].mean, t.mean[c].mean, 4 * se + 1e-6 * t.mean[c].mean)
          << what << " seed " << seed << " channel " << c;
    }
  }
}

// The standard deviation of the mean red over the close-up's 8 x 8 cells of 8 px (the film's
// edges lie on cell edges: it spans -1 .. 1 cm).
double cell_spread(const Image& im) {
  std::vector<double> means;
  for (int cy = 0; cy < 8; ++cy)
    for (int cx = 0; cx < 8; ++cx) {
      double sum = 0;
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) sum += im.rgb[3 * ((cy * 8 + y) * im.width + cx * 8 + x)];
      means.push_back(sum / 64);
    }
  return sample_mean(64, [&](int i) { return means[i]; }).std_error * 8;  // std-dev
}

class WeaveLevelRender : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path dir = fresh_test_dir();
    files_ = {write_fabric_table(dir), write_checker_weave(dir)};
  }
  Files files_;
};

}  // namespace

// (a) weave level and (b) table level seen from afar (0.64 px a repeat, 100 x 100 repeats on the
// film): the same mean, lit from the front and through the cloth from behind.
TEST_F(WeaveLevelRender, FarAwayBothLevelsHaveTheSameMeanFrontAndBack) {
  for (bool behind : {false, true}) {
    expect_same_means(patch_scene(files_, "weave", kFar_m, behind),
                      patch_scene(files_, "table", kFar_m, behind),
                      behind ? "far, lit from behind" : "far, lit from the front");
  }
}

// (c) Up close (32 px a repeat, 2 x 2 whole repeats on the film): the same mean over the whole
// repeats, and structure at the scale of the weave's cells: the standard deviation of the 8 x 8
// cells' mean red is several times the table level's, whose cells differ by noise alone.
TEST_F(WeaveLevelRender, CloseUpShowsTheCellsAndKeepsTheMean) {
  for (bool behind : {false, true}) {
    const auto weave = patch_scene(files_, "", kClose_m, behind);  // auto: the weave level
    const auto table = patch_scene(files_, "table", kClose_m, behind);
    expect_same_means(weave, table,
                      behind ? "close, lit from behind" : "close, lit from the front");
    const double sw = cell_spread(render_patch(weave, 1).result.image);
    const double st = cell_spread(render_patch(table, 1).result.image);
    std::printf("close (%s): std-dev of the cells' mean red: weave %.4g table %.4g ratio %.1f\n",
                behind ? "behind" : "front", sw, st, sw / st);
    EXPECT_GT(sw, 5 * st);
  }
}

// (d) auto chooses per object from the footprint: the weave level up close (32 px a repeat), the
// table level far away (0.64 px); the render reports it as its --json does.
TEST_F(WeaveLevelRender, AutoChoosesByFootprintAndTheRenderReportsIt) {
  for (double distance : {kClose_m, kFar_m}) {
    const SceneDescription d = patch_scene(files_, "auto", distance, false);
    // One pixel at distance D spans 2 D tan(yfov / 2) / height (weave_level.h).
    const double expect_px = kRepeat_m / (2 * distance * kHalfFov / kPixels);
    const auto levels = choose_weave_levels(RenderScene(d), *d.camera, settings(1));
    ASSERT_EQ(levels.size(), 1u);
    EXPECT_NEAR(levels[0].repeat_pixels, expect_px, 1e-9 * expect_px);
    EXPECT_EQ(levels[0].weave, distance == kClose_m);
    RenderSettings s = settings(1);
    s.spp = 1;
    const RenderResult r = render(RenderScene(d), *d.camera, s);
    const nlohmann::json j = weave_levels_json(r.weave_levels);
    ASSERT_EQ(j.size(), 1u);
    EXPECT_EQ(j[0]["object"], "patch");
    EXPECT_EQ(j[0]["mesh"], 0);
    EXPECT_EQ(j[0]["setting"], "auto");
    EXPECT_EQ(j[0]["level"], distance == kClose_m ? "weave" : "table");
    EXPECT_NEAR(j[0]["repeat_pixels"].get<double>(), expect_px, 1e-9 * expect_px);
  }
}

TEST(ChooseWeaveLevel, ThresholdsAndFootprints) {
  EXPECT_TRUE(weave_level_chosen(WeaveLevel::automatic, 4, 4));  // "at least" the minimum
  EXPECT_FALSE(weave_level_chosen(WeaveLevel::automatic, 3.99, 4));
  EXPECT_TRUE(weave_level_chosen(WeaveLevel::weave, 0.1, 4));
  EXPECT_FALSE(weave_level_chosen(WeaveLevel::table, 1000, 4));
  Bounds3 box;
  box.expand(Vec3{-1, -1, 0});
  box.expand(Vec3{1, 1, 0});
  Camera cam = Camera::look_at(Camera::Type::perspective, {0, 0, 5}, {0, 0, 0}, {0, 1, 0});
  cam.yfov_rad = 2 * std::atan(0.5);  // film 5 m high at 5 m: 100 px of 5 cm
  EXPECT_NEAR(repeat_pixels(cam, 100, box, 0.1), 2.0, 1e-12);
  cam.position = {3, 1, 4};  // nearest point (1, 1, 0): distance sqrt(4 + 16)
  EXPECT_NEAR(repeat_pixels(cam, 100, box, 0.1), 0.1 / (2 * std::sqrt(20.0) * 0.5 / 100), 1e-12);
  cam.position = {0, 0, 0};  // inside the (flat) box: any repeat is resolved
  EXPECT_TRUE(std::isinf(repeat_pixels(cam, 100, box, 0.1)));
  Camera ortho = cam;
  ortho.type = Camera::Type::orthographic;
  ortho.half_height = 0.5;  // 1 m over 100 px: 1 cm a pixel, at any distance
  EXPECT_NEAR(repeat_pixels(ortho, 100, box, 0.03), 3.0, 1e-12);
}

// A spectral render reads a spectral weave per band: the same mean as the table level over the
// close-up's whole repeats, and the cells show in red (bands 390-490 nm and 500-600 nm carry the
// checker; the red of linear sRGB takes its positive weights from both).
TEST_F(WeaveLevelRender, SpectralWeaveRendersPerBand) {
  const fs::path dir = fresh_test_dir();
  const Files spectral{write_fabric_table(dir, kNumBands), write_checker_weave(dir, kNumBands)};
  const auto weave = patch_scene(spectral, "weave", kClose_m, false);
  const auto table = patch_scene(spectral, "table", kClose_m, false);
  expect_same_means(weave, table, "close, spectral", true);
  const double sw = cell_spread(render_patch(weave, 1, true).result.image);
  const double st = cell_spread(render_patch(table, 1, true).result.image);
  std::printf("close, spectral: std-dev of the cells' mean red: weave %.4g table %.4g\n", sw, st);
  EXPECT_GT(sw, 5 * st);
}

// The scene's side: a woven mesh needs UVs; the level as built is the material's forced one
// ("weave": on; "auto" and "table": off until a render chooses); with_weave_levels checks sizes.
TEST_F(WeaveLevelRender, SceneKnowsItsWovenMeshes) {
  for (const char* level : {"weave", "auto", "table"}) {
    const RenderScene scene(patch_scene(files_, level, kFar_m, false));
    ASSERT_EQ(scene.woven_meshes().size(), 1u);
    EXPECT_EQ(scene.woven_meshes()[0].name, "patch");
    EXPECT_EQ(scene.weave_level(0), std::string(level) == "weave") << level;
    EXPECT_TRUE(scene.with_weave_levels({1}).weave_level(0));
    EXPECT_FALSE(scene.with_weave_levels({0}).weave_level(0));
    EXPECT_NE(error_of([&] { scene.with_weave_levels({}); }), "");
  }
  SceneDescription no_uv = patch_scene(files_, "", kFar_m, false);
  auto mesh = std::make_shared<TriangleMesh>(*no_uv.meshes[0]);
  mesh->uvs.clear();
  no_uv.meshes = {mesh};
  const std::string msg = error_of([&] { RenderScene{no_uv}; });
  EXPECT_NE(msg.find("materials.cloth"), std::string::npos) << msg;
  EXPECT_NE(msg.find("UVs"), std::string::npos) << msg;
}
