// The render controls users expect: a crop window holds the same pixels as the whole
// render, a time limit stops after whole passes, albedo and normal passes leave the image alone,
// and a render's EXR carries its metadata and is the same bytes on every run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/integrators/image.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_job.h"
#include "weft/scenes/render_scene.h"
#include "woven_patch.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(RenderControls, CropWindowHoldsTheSamePixelsAsTheWholeRender) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  const RenderResult full = render(scene, *d.camera, small_render_settings(1));
  RenderSettings s = small_render_settings(2);
  s.crop = PixelWindow{7, 30, 5, 21};  // across tile borders (tiles of 16)
  const RenderResult crop = render(scene, *d.camera, s);
  ASSERT_EQ(crop.image.width, 23);
  ASSERT_EQ(crop.image.height, 16);
  EXPECT_EQ(crop.image.x0, 7);
  EXPECT_EQ(crop.image.y0, 5);
  EXPECT_EQ(crop.image.film_width, 45);
  EXPECT_EQ(crop.image.film_height, 37);
  double total = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 23; ++x) {
      const Rgb a = crop.image.at(x, y), b = full.image.at(7 + x, 5 + y);
      ASSERT_EQ(a.r, b.r) << x << "," << y;
      ASSERT_EQ(a.g, b.g);
      ASSERT_EQ(a.b, b.b);
      total += a.r;
    }
  EXPECT_GT(total, 0);
  // Only the window's samples are taken.
  EXPECT_EQ(crop.rays.camera, uint64_t(23) * 16 * 3);
}

TEST(RenderControls, CropOutsideTheFilmIsAnError) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  for (const PixelWindow w : {PixelWindow{0, 46, 0, 37}, PixelWindow{5, 5, 0, 37},
                              PixelWindow{-1, 10, 0, 37}, PixelWindow{0, 10, 20, 10}}) {
    RenderSettings s = small_render_settings(1);
    s.crop = w;
    EXPECT_NE(error_of([&] { render(scene, *d.camera, s); }).find("x0 < x1 <= width"),
              std::string::npos);
  }
}

TEST(RenderControls, TimeLimitEndsAfterWholePasses) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  // A limit that every pass exceeds: one pass, the same bits as a render of 1 sample per pixel.
  RenderSettings s = small_render_settings(2);
  s.time_limit_s = 1e-9;
  const RenderResult one_pass = render(scene, *d.camera, s);
  EXPECT_EQ(one_pass.spp_done, 1);
  RenderSettings one = small_render_settings(1);
  one.spp = 1;
  EXPECT_TRUE(same_bits(one_pass.image.rgb, render(scene, *d.camera, one).image.rgb));
  // A limit never reached: every pass, the same bits as the render without a limit.
  s.time_limit_s = 1e9;
  const RenderResult all = render(scene, *d.camera, s);
  EXPECT_EQ(all.spp_done, 3);
  const RenderResult plain = render(scene, *d.camera, small_render_settings(1));
  EXPECT_EQ(plain.spp_done, 3);
  EXPECT_TRUE(same_bits(all.image.rgb, plain.image.rgb));
  EXPECT_FALSE(same_bits(all.image.rgb, one_pass.image.rgb));  // the comparisons can fail
  EXPECT_EQ(all.rays.total(), plain.rays.total());
}

TEST(RenderControls, AlbedoAndNormalOfALambertPlane) {
  // A Lambert plane (reflectance 0.25, 0.5, 0.75) filling an orthographic view from above: its
  // albedo is the reflectance (a cosine-sampled Lambert sample weighs exactly the reflectance) and
  // its normal +y, in every pixel.
  const nlohmann::json j = {
      {"objects",
       {{{"type", "quad"},
         {"material", "m"},
         {"center", {0, 0, 0}},
         {"normal", {0, 1, 0}},
         {"size", {4, 4}}}}},
      {"materials",
       {{"m", {{"type", "lambert"}, {"params", {{"reflectance", {0.25, 0.5, 0.75}}}}}}}},
      {"lights", {{{"type", "parallel"}, {"irradiance", 1}}}},
      {"camera",
       {{"type", "orthographic"},
        {"position", {0, 1, 0}},
        {"look_at", {0, 0, 0}},
        {"up", {0, 0, -1}},
        {"half_width", 1},
        {"half_height", 1}}}};
  const SceneDescription d = parse_scene_description(j, ".", "plane.json");
  const RenderScene scene(d);
  RenderSettings s = small_render_settings(2);
  s.aov_albedo = s.aov_normal = true;
  const RenderResult r = render(scene, *d.camera, s);
  ASSERT_EQ(r.albedo.width, s.width);
  ASSERT_EQ(r.normal.height, s.height);
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      ASSERT_NEAR(r.albedo.at(x, y).r, 0.25, 1e-6);
      ASSERT_NEAR(r.albedo.at(x, y).g, 0.5, 1e-6);
      ASSERT_NEAR(r.albedo.at(x, y).b, 0.75, 1e-6);
      ASSERT_NEAR(r.normal.at(x, y).g, 1.0, 1e-6);
    }
  // The passes only observe: the image is the one rendered without them.
  EXPECT_TRUE(same_bits(r.image.rgb, render(scene, *d.camera, small_render_settings(1)).image.rgb));
  EXPECT_TRUE(render(scene, *d.camera, small_render_settings(1)).albedo.rgb.empty());
}

TEST(RenderControls, AlbedoAndNormalPassesAreDeterministicOnTheWovenPatch) {
  const SceneDescription d = lit_woven_patch();
  const RenderScene scene(d);
  RenderSettings a = small_render_settings(1), b = small_render_settings(0);
  a.aov_albedo = a.aov_normal = b.aov_albedo = b.aov_normal = true;
  const RenderResult ra = render(scene, *d.camera, a), rb = render(scene, *d.camera, b);
  EXPECT_TRUE(same_bits(ra.albedo.rgb, rb.albedo.rgb));
  EXPECT_TRUE(same_bits(ra.normal.rgb, rb.normal.rgb));
  // Albedo of the Lambert yarns is at most the largest reflectance, normals are unit or zero
  // (a camera ray that misses) averaged: at most unit length.
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      EXPECT_LE(ra.albedo.at(x, y).max_component(), 0.6 + 1e-6);
      const Rgb n = ra.normal.at(x, y);
      EXPECT_LE(n.r * n.r + n.g * n.g + n.b * n.b, 1 + 1e-5);
    }
}

TEST(RenderControls, ExrIsTheSameBytesOnEveryRunAndCarriesMetadata) {
  const fs::path dir = fresh_test_dir();
  SceneDescription d = lit_woven_patch();
  d.source = "/somewhere/woven.json";
  // A perspective view of the patch from above and aside, at about twice its size.
  const Bounds3 box = d.object_bounds("");
  const Vec3 centre = (box.lo + box.hi) * 0.5;
  const double size = length(box.hi - box.lo);
  d.camera = Camera::look_at(Camera::Type::perspective, centre + Vec3{0.3, 2.0, 1.5} * size, centre,
                             {0, 1, 0});
  d.camera->yfov_rad = deg_to_rad(35);
  RenderJob job;
  job.settings = small_render_settings(2);
  job.settings.seed = 77;
  job.exr = dir / "a.exr";
  render_to_files(d, job);
  job.exr = dir / "b.exr";
  job.settings.threads = 1;
  render_to_files(d, job);
  const std::string a = slurp(dir / "a.exr"), b = slurp(dir / "b.exr");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);  // no date, no host: the same bytes

  const nlohmann::json m = read_image_metadata(dir / "a.exr");
  EXPECT_EQ(m.at("weft:spp"), 3);
  EXPECT_EQ(m.at("weft:spp_requested"), 3);
  EXPECT_EQ(m.at("weft:seed"), "77");
  EXPECT_EQ(m.at("weft:scene"), "woven.json");
  EXPECT_EQ(m.at("weft:version"), WEFT_TEST_VERSION);
  EXPECT_FALSE(m.contains("DateTime"));
  // sRGB / Rec. 709 primaries and D65 (IEC 61966-2-1).
  const std::vector<double> chroma = m.at("chromaticities");
  const double expected[8] = {0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290};
  ASSERT_EQ(chroma.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(chroma[i], expected[i], 1e-6);

  // worldToNDC takes the point a camera ray through film point (fx, fy) reaches back to (fx, fy);
  // worldToCamera takes it to depth t along the view.
  const std::vector<double> ndc = m.at("worldToNDC"), cam = m.at("worldToCamera");
  ASSERT_EQ(ndc.size(), 16u);
  ASSERT_EQ(cam.size(), 16u);
  const double aspect = 45.0 / 37.0;
  for (const auto& [fx, fy] : {std::pair{0.5, 0.5}, {0.1, 0.8}, {0.95, 0.05}}) {
    const Ray ray = d.camera->generate_ray(fx, fy, aspect);
    const Vec3 p = ray.o + ray.d * (2.5 * size);
    const double v[4] = {p.x, p.y, p.z, 1};
    double h[4] = {0, 0, 0, 0}, c[4] = {0, 0, 0, 0};
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) h[j] += v[i] * ndc[4 * i + j], c[j] += v[i] * cam[4 * i + j];
    EXPECT_NEAR(h[0] / h[3], fx, 1e-5);
    EXPECT_NEAR(h[1] / h[3], fy, 1e-5);
    EXPECT_NEAR(c[2], 2.5 * size * dot(ray.d, d.camera->forward), 1e-5 * size);
    EXPECT_NEAR(c[0], dot(p - d.camera->position, d.camera->right), 1e-5 * size);
  }
}

TEST(RenderControls, PassesAreFilesWithTheImagesMetadata) {
  const fs::path dir = fresh_test_dir();
  const SceneDescription d = lit_woven_patch();
  RenderJob job;
  job.settings = small_render_settings(2);
  job.exr = dir / "out.exr";
  job.albedo = dir / "out.albedo.exr";
  job.normal = dir / "out.normal.exr";
  render_to_files(d, job);
  const Image albedo = read_image(*job.albedo);
  EXPECT_EQ(albedo.width, 45);
  EXPECT_EQ(read_image_metadata(*job.albedo).at("weft:content"), "albedo");
  EXPECT_EQ(read_image_metadata(*job.normal).at("weft:spp"), 3);
  // The image is the one rendered without passes.
  const RenderResult plain = render(RenderScene(d), *d.camera, small_render_settings(1));
  EXPECT_TRUE(same_bits(read_image(job.exr).rgb, plain.image.rgb));
}

TEST(RenderControls, CroppedExrKeepsItsPlaceOnTheFilm) {
  const fs::path dir = fresh_test_dir();
  const SceneDescription d = lit_woven_patch();
  RenderJob job;
  job.settings = small_render_settings(2);
  job.settings.crop = PixelWindow{3, 20, 10, 30};
  job.exr = dir / "crop.exr";
  render_to_files(d, job);
  const Image back = read_image(job.exr);
  EXPECT_EQ(back.width, 17);
  EXPECT_EQ(back.height, 20);
  EXPECT_EQ(back.x0, 3);
  EXPECT_EQ(back.y0, 10);
  EXPECT_EQ(back.film_width, 45);
  EXPECT_EQ(back.film_height, 37);
}

TEST(RenderControls, OutputsThatClashAreRefusedBeforeRendering) {
  const fs::path dir = fresh_test_dir();
  SceneDescription d = lit_woven_patch();
  RenderJob job;
  job.settings = small_render_settings(1);
  job.exr = dir / "out.exr";
  job.albedo = dir / "out.exr";
  EXPECT_NE(error_of([&] { render_to_files(d, job); }).find("is also the output file"),
            std::string::npos);
  job.albedo.reset();
  job.mask = dir / "." / "out.exr";
  job.mask_object = "warp";
  EXPECT_NE(error_of([&] { render_to_files(d, job); }).find("is also the output file"),
            std::string::npos);
  job.mask.reset();
  std::ofstream(dir / "scene.exr") << "{}";
  d.source = (dir / "scene.exr").string();
  job.exr = dir / "scene.exr";
  EXPECT_NE(error_of([&] { render_to_files(d, job); }).find("scene description"),
            std::string::npos);
  // A mask is of the whole film: not with a crop window.
  job.exr = dir / "out.exr";
  job.mask = dir / "mask.exr";
  job.settings.crop = PixelWindow{0, 10, 0, 10};
  EXPECT_NE(error_of([&] { render_to_files(d, job); }).find("crop"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
  EXPECT_FALSE(fs::exists(dir / "mask.exr"));
}

TEST(RenderControls, RenderSectionTakesCropAndTimeLimit) {
  auto with_render = [](const nlohmann::json& render) {
    const nlohmann::json j = {
        {"objects",
         {{{"type", "quad"}, {"material", "m"}, {"center", {0, 0, 0}}, {"normal", {0, 1, 0}}}}},
        {"materials", {{"m", {{"type", "lambert"}}}}},
        {"render", render}};
    return render_settings_from(parse_scene_description(j, ".", "scene.json"));
  };
  const RenderSettings s =
      with_render({{"width", 64}, {"height", 32}, {"crop", {1, 9, 2, 30}}, {"time_limit_s", 5}});
  ASSERT_TRUE(s.crop.has_value());
  EXPECT_EQ(*s.crop, (PixelWindow{1, 9, 2, 30}));
  EXPECT_EQ(s.time_limit_s, 5);
  EXPECT_FALSE(with_render({{"spp", 4}}).crop.has_value());
  for (const nlohmann::json& bad : {nlohmann::json{1, 9, 2}, nlohmann::json{1, 9, 2, 40},
                                    nlohmann::json{1.5, 9, 2, 20}, nlohmann::json{9, 1, 2, 20}}) {
    const std::string e = error_of([&] {
      with_render({{"width", 64}, {"height", 32}, {"crop", bad}});
    });
    EXPECT_NE(e.find("scene.json: field 'render.crop"), std::string::npos) << e;
  }
  EXPECT_NE(error_of([&] {
              with_render({{"time_limit_s", -1}});
            }).find("render.time_limit_s"),
            std::string::npos);
}
