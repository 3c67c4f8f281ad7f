// weft render's controls as a user meets them: -D overrides, --camera, --crop,
// --exposure, --time-limit, --aov, EXR metadata and bit-identical files, progress in a log.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>
#include <string>

#include "cli_run.h"
#include "test_util.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/image.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_table.h"

namespace fs = std::filesystem;
using namespace weft::testing;

namespace {

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// The bundled Lambert plane, small and quick.
std::string plane(const fs::path& out, const std::string& more = "", int spp = 2) {
  return "render '" + (kExamples / "lambert-plane.json").string() +
         "' --width 24 --height 20 --spp " + std::to_string(spp) + " --quiet -o '" + out.string() +
         "' " + more;
}

// The bundled plane's glTF with two cameras above it looking down: node 1 holds an unnamed
// perspective camera, node 2 an orthographic one named "top". A description binds the plane.
fs::path scene_with_cameras(const fs::path& dir) {
  nlohmann::json g = nlohmann::json::parse(slurp(kExamples / "lambert-plane.gltf"));
  // Buffers are embedded (data URIs) or beside the file: copy whatever the plane refers to.
  for (auto& b : g["buffers"])
    if (b.contains("uri") && b["uri"].get<std::string>().rfind("data:", 0) != 0)
      fs::copy_file(kExamples / b["uri"].get<std::string>(), dir / b["uri"].get<std::string>(),
                    fs::copy_options::overwrite_existing);
  const double s = std::sqrt(0.5);  // -90 degrees about x: the camera's -z points down
  g["cameras"] = {
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.01}}}},
      {{"type", "orthographic"},
       {"orthographic", {{"xmag", 0.3}, {"ymag", 0.3}, {"znear", 0.01}, {"zfar", 10}}}}};
  g["nodes"].push_back({{"camera", 0}, {"translation", {0, 2, 0}}, {"rotation", {-s, 0, 0, s}}});
  g["nodes"].push_back(
      {{"name", "top"}, {"camera", 1}, {"translation", {0, 2, 0}}, {"rotation", {-s, 0, 0, s}}});
  g["scenes"][0]["nodes"] = {0, 1, 2};
  std::ofstream(dir / "cams.gltf") << g.dump();
  const nlohmann::json d = {
      {"gltf", "cams.gltf"},
      {"materials", {{"plane", {{"type", "lambert"}, {"params", {{"reflectance", 0.5}}}}}}},
      {"lights", {{{"type", "parallel"}, {"irradiance", 1}, {"zenith_deg", 30}}}},
      {"render", {{"width", 16}, {"height", 16}, {"spp", 2}}}};
  std::ofstream(dir / "cams.json") << d.dump(2);
  return dir / "cams.json";
}

}  // namespace

TEST(CliRender, DefineOverridesAMaterialParameter) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli(plane(dir / "half.exr"), dir).exit_code, 0);
  const CliRun r =
      run_weft_cli(plane(dir / "quarter.exr", "-D materials.plane.params.reflectance=0.25"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Direct light on a lone Lambert plane is reflectance / pi x E cos: halving the reflectance
  // halves every pixel exactly (a power of two).
  const weft::Image half = weft::read_image(dir / "half.exr"),
                    quarter = weft::read_image(dir / "quarter.exr");
  ASSERT_EQ(half.rgb.size(), quarter.rgb.size());
  double lit = 0;
  for (size_t i = 0; i < half.rgb.size(); ++i) {
    ASSERT_EQ(quarter.rgb[i], half.rgb[i] * 0.5f) << i;
    lit += half.rgb[i];
  }
  EXPECT_GT(lit, 0);
  // render.spp reaches the render settings (--spp not given).
  const CliRun s = run_weft_cli("render '" + (kExamples / "lambert-plane.json").string() +
                                    "' --width 8 --height 8 -D render.spp=3 --quiet --json -o '" +
                                    (dir / "spp.exr").string() + "'",
                                dir);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(nlohmann::json::parse(s.out).at("spp"), 3);
}

TEST(CliRender, DefineErrorsNameTheKeyAndTheFileAndWriteNothing) {
  const fs::path dir = fresh_test_dir();
  for (const auto& [define, part] :
       {std::pair<std::string, std::string>{"materials.cloth.params.reflectance=0.5",
                                            "has no 'cloth'"},
        {"render.spp=many", "is a number in the description, but 'many' is text"},
        {"lights[3].irradiance=2", "has 1 entry (indices 0 to 0)"},
        {"render.spp", "is not key=value"}}) {
    const CliRun r = run_weft_cli(plane(dir / "out.exr", "-D " + define), dir);
    EXPECT_EQ(r.exit_code, 2) << define;
    EXPECT_TRUE(contains(r.err, part)) << r.err;
    if (define.find('=') != std::string::npos) {
      EXPECT_TRUE(contains(r.err, "lambert-plane.json")) << r.err;
      EXPECT_TRUE(contains(r.err, "-D " + define.substr(0, define.find('=')))) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
}

TEST(CliRender, CameraByNameOrIndexAndTheErrorListsThem) {
  const fs::path dir = fresh_test_dir();
  const fs::path scene = scene_with_cameras(dir);
  auto render_with = [&](const std::string& camera, const fs::path& out) {
    return run_weft_cli(
        "render '" + scene.string() + "' --quiet --camera " + camera + " -o '" + out.string() + "'",
        dir);
  };
  CliRun r = render_with("0", dir / "persp.exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = render_with("top", dir / "top.exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(weft::read_image_metadata(dir / "top.exr").at("weft:camera"), "top");
  // The orthographic camera sees 0.6 m of the 1 m plane: every pixel is lit plane. The
  // perspective one (yfov 0.6 rad from 2 m: 1.25 m) sees past the plane's edges.
  const weft::Image top = weft::read_image(dir / "top.exr"),
                    persp = weft::read_image(dir / "persp.exr");
  EXPECT_GT(*std::min_element(top.rgb.begin(), top.rgb.end()), 0.0f);
  EXPECT_EQ(*std::min_element(persp.rgb.begin(), persp.rgb.end()), 0.0f);
  r = render_with("2", dir / "none.exr");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "cams.json")) << r.err;
  EXPECT_TRUE(contains(r.err, "no camera with index 2")) << r.err;
  EXPECT_TRUE(contains(r.err, "0 (unnamed), 1 'top'")) << r.err;
  EXPECT_FALSE(fs::exists(dir / "none.exr"));
  r = render_with("side", dir / "none.exr");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "no camera named 'side'")) << r.err;
}

TEST(CliRender, CropIsTheSameWindowOfTheWholeRender) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli(plane(dir / "full.exr"), dir).exit_code, 0);
  const CliRun r = run_weft_cli(plane(dir / "crop.exr", "--crop 3,17,2,11"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const weft::Image full = weft::read_image(dir / "full.exr"),
                    crop = weft::read_image(dir / "crop.exr");
  ASSERT_EQ(crop.width, 14);
  ASSERT_EQ(crop.height, 9);
  EXPECT_EQ(crop.x0, 3);
  EXPECT_EQ(crop.y0, 2);
  EXPECT_EQ(crop.film_width, 24);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 14; ++x) ASSERT_EQ(crop.at(x, y).g, full.at(3 + x, 2 + y).g);
  for (const std::string bad : {"3,17,2", "3,30,2,11", "5,3,2,11", "a,b,c,d", "1.5,3,2,11"}) {
    const CliRun b = run_weft_cli(plane(dir / "bad.exr", "--crop " + bad), dir);
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_TRUE(contains(b.err, "--crop")) << b.err;
    EXPECT_FALSE(fs::exists(dir / "bad.exr"));
  }
}

TEST(CliRender, ExposureScalesThePreviewOnly) {
  const fs::path dir = fresh_test_dir();
  const CliRun r = run_weft_cli(
      plane(dir / "out.exr", "--exposure 1 --preview '" + (dir / "out.png").string() + "'"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(run_weft_cli(plane(dir / "plain.exr"), dir).exit_code, 0);
  const weft::Image exr = weft::read_image(dir / "out.exr"),
                    png = weft::read_image(dir / "out.png");
  EXPECT_EQ(exr.rgb, weft::read_image(dir / "plain.exr").rgb);  // the EXR is unchanged
  ASSERT_EQ(png.rgb.size(), exr.rgb.size());
  // +1 EV doubles the linear value, then clips to [0, 1] and encodes sRGB (8 bits).
  for (size_t i = 0; i < exr.rgb.size(); ++i) {
    const double expect =
        std::lround(255 * weft::linear_to_srgb_gamma(std::min(1.0, 2.0 * exr.rgb[i]))) / 255.0;
    ASSERT_NEAR(png.rgb[i], expect, 1e-6) << i;
  }
}

TEST(CliRender, OutputFormatFollowsTheExtension) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli(
                plane(dir / "out.exr", "--preview '" + (dir / "preview.png").string() + "'"), dir)
                .exit_code,
            0);
  ASSERT_EQ(run_weft_cli(plane(dir / "out.png"), dir).exit_code, 0);
  ASSERT_EQ(run_weft_cli(plane(dir / "out.hdr"), dir).exit_code, 0);
  const weft::Image exr = weft::read_image(dir / "out.exr"),
                    png = weft::read_image(dir / "out.png"),
                    hdr = weft::read_image(dir / "out.hdr");
  // -o .png is the preview of the same render (same seed: the same pixels).
  EXPECT_EQ(png.rgb, weft::read_image(dir / "preview.png").rgb);
  // -o .hdr is linear: Radiance RGBE keeps 8-bit mantissas under a shared exponent (Ward, "Real
  // Pixels", Graphics Gems II), so each channel is within 1/128 of the pixel's largest channel.
  ASSERT_EQ(hdr.width, exr.width);
  ASSERT_EQ(hdr.rgb.size(), exr.rgb.size());
  for (size_t i = 0; i < exr.rgb.size(); i += 3) {
    const float top = std::max({exr.rgb[i], exr.rgb[i + 1], exr.rgb[i + 2]});
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(hdr.rgb[i + c], exr.rgb[i + c], top / 128) << i;
  }
  // Another extension is refused before any work, naming the output.
  const CliRun bad = run_weft_cli(plane(dir / "out.tif"), dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(contains(bad.err, ".png or .hdr")) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "out.tif"));
}

TEST(CliRender, TimeLimitWritesWholePassesAndSaysHowMany) {
  const fs::path dir = fresh_test_dir();
  const CliRun r = run_weft_cli(plane(dir / "out.exr", "--time-limit 1e-9 --json", 64), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("spp_done"), 1);
  const nlohmann::json m = weft::read_image_metadata(dir / "out.exr");
  EXPECT_EQ(m.at("weft:spp"), 1);
  EXPECT_EQ(m.at("weft:spp_requested"), 64);
  EXPECT_TRUE(m.contains("weft:time_limit_s"));
  // One pass is a render of 1 sample per pixel.
  ASSERT_EQ(run_weft_cli(plane(dir / "one.exr", "", 1), dir).exit_code, 0);
  EXPECT_EQ(weft::read_image(dir / "out.exr").rgb, weft::read_image(dir / "one.exr").rgb);
}

// --spectral: light per band (docs/scenes.md "Spectral renders"). The bundled plane is grey (the
// same at every wavelength), so the image is the RGB render's reduced to the reduction's white; a
// coloured reflectance is refused, naming the material, with nothing written.
TEST(CliRender, SpectralRendersGreyScenesAndRefusesRgbColours) {
  const fs::path dir = fresh_test_dir();
  const CliRun a = run_weft_cli(plane(dir / "spectral.exr", "--spectral", 11), dir);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(run_weft_cli(plane(dir / "rgb.exr", "", 11), dir).exit_code, 0);
  const auto s = weft::read_image(dir / "spectral.exr"), r = weft::read_image(dir / "rgb.exr");
  ASSERT_EQ(s.rgb.size(), r.rgb.size());
  // A grey spectrum reduces to the reduction's white, the sum of the band weights (1 to 1e-3: the
  // sRGB matrix's white is D65 to its printed digits).
  double white[3] = {0, 0, 0};
  for (const weft::Rgb& w : weft::srgb_band_weights_d65())
    white[0] += w.r, white[1] += w.g, white[2] += w.b;
  for (size_t i = 0; i < s.rgb.size(); ++i)
    ASSERT_NEAR(s.rgb[i], r.rgb[i] * white[i % 3], 1e-5 * r.rgb[i]) << i;
  EXPECT_TRUE(contains(
      weft::read_image_metadata(dir / "spectral.exr").at("weft:content").get<std::string>(),
      "33 bands"));
  const CliRun bad = run_weft_cli(
      plane(dir / "red.exr", "--spectral -D materials.plane.params.reflectance=[0.5,0.2,0.1]"),
      dir);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.err, "materials.plane")) << bad.err;
  EXPECT_TRUE(contains(bad.err, "lambert")) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "red.exr"));
}

TEST(CliRender, AovPassesAreFilesBesideTheImage) {
  const fs::path dir = fresh_test_dir();
  const CliRun r = run_weft_cli(plane(dir / "out.exr", "--aov albedo,normal"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const weft::Image albedo = weft::read_image(dir / "out.albedo.exr");
  const weft::Image normal = weft::read_image(dir / "out.normal.exr");
  // The plane (reflectance 0.5, normal +y) fills the bundled camera's view.
  EXPECT_NEAR(albedo.at(12, 10).r, 0.5, 1e-6);
  EXPECT_NEAR(normal.at(12, 10).g, 1.0, 1e-6);
  const CliRun bad = run_weft_cli(plane(dir / "bad.exr", "--aov albedo,depth"), dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(contains(bad.err, "unknown pass 'depth' (valid: albedo, normal)")) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

TEST(CliRender, ExrIsBitIdenticalAcrossRuns) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli(plane(dir / "a.exr"), dir).exit_code, 0);
  ASSERT_EQ(run_weft_cli(plane(dir / "b.exr", "--threads 1"), dir).exit_code, 0);
  const std::string a = slurp(dir / "a.exr"), b = slurp(dir / "b.exr");
  ASSERT_GT(a.size(), 500u);
  EXPECT_TRUE(a == b) << "the two renders' files differ";
  const nlohmann::json m = weft::read_image_metadata(dir / "a.exr");
  EXPECT_EQ(m.at("weft:scene"), "lambert-plane.json");
  EXPECT_EQ(m.at("weft:seed"), "1");  // the bundled scene's render.seed
  EXPECT_EQ(m.at("weft:spp"), 2);
  EXPECT_TRUE(m.contains("worldToCamera"));
  EXPECT_TRUE(m.contains("worldToNDC"));
  EXPECT_TRUE(m.contains("chromaticities"));
}

TEST(CliRender, ProgressInALogIsPlainLinesWithUnits) {
  const fs::path dir = fresh_test_dir();
  const CliRun r =
      run_weft_cli("render '" + (kExamples / "lambert-plane.json").string() +
                       "' --width 24 --height 20 --spp 2 -o '" + (dir / "out.exr").string() + "'",
                   dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_TRUE(contains(r.err, "render  100.0%")) << r.err;
  EXPECT_TRUE(contains(r.err, "samples/s")) << r.err;
  EXPECT_TRUE(contains(r.err, "ETA 00:00")) << r.err;
  EXPECT_TRUE(contains(r.err, "rays/s")) << r.err;  // the summary
  EXPECT_TRUE(contains(r.err, "2 of 2 samples per pixel")) << r.err;
}

// Ctrl-C was seen only where a tile ended: a 16 x 16 render at 2^20 samples per pixel is one
// tile, and stopped about 110 s after the signal. The renderer asks the progress callback every
// 4096 samples of a thread (path_tracer.cpp kPollSamples), so it stops within a fraction of a
// second: 10 s allows for a loaded machine. Nothing is written, exit 130.
TEST(CliRender, CtrlCStopsALargeTileAtOnce) {
  const fs::path dir = fresh_test_dir();
  std::string cmd = "cd '";
  cmd += dir.string() + "'; '" + WEFT_EXE + "' render '" +
         (kExamples / "lambert-plane.json").string() +
         "' --width 16 --height 16 --spp 1048576 -o out.exr --quiet 2>err & "
         // A background job of sh starts with SIGINT ignored until weft catches it: wait for its
         // handler (SigCgt holds SIGINT, bit 1) so a slow start on a loaded machine is not a
         // signal lost, then let the render run a moment.
         "pid=$!; n=0; while [ $n -lt 1200 ]; do "
         "m=$(awk '/^SigCgt/ {print $2}' /proc/$pid/status 2>/dev/null); "
         "[ -n \"$m\" ] && [ $(( 0x$m & 2 )) -ne 0 ] && break; n=$((n+1)); sleep 0.05; done; "
         "sleep 0.5; t0=$(date +%s%N); kill -INT $pid; wait $pid; "
         "echo $? $(( ($(date +%s%N) - t0) / 1000000 )) > result";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::istringstream in(slurp(dir / "result"));
  int code = -1;
  long ms = -1;
  in >> code >> ms;
  EXPECT_EQ(code, 130) << slurp(dir / "err");
  EXPECT_GE(ms, 0);
  EXPECT_LT(ms, 10000) << "ms from the signal to the exit";
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

// The bundled plane (1 m, framed by an orthographic camera: 20 px high is 5 cm a pixel) as a
// fabric_table with a weave of repeat 0.5 m (10 px): auto chooses the weave level at the default
// weave_min_pixels (4) and the table level when it asks for 1000; --json says which.
TEST(CliRender, JsonReportsTheWeaveLevelChosenPerObject) {
  const fs::path dir = fresh_test_dir();
  auto table = weft::TabulatedBsdfTable::from_function(
      2, 3,
      [](const weft::Vec3&, const weft::Vec3&, std::span<double> v) { v[0] = v[1] = v[2] = 0.1; },
      1, 1);
  table.kind = "fabric";
  table.write_exr(dir / "fabric.exr");
  weft::WeaveTable weave;
  weave.resolution = 1;
  weave.positions_u = weave.positions_v = 2;
  weave.repeat_u_m = weave.repeat_v_m = 0.5;
  weave.modulation = std::vector<float>(4 * 2 * 2 * 3, 1.0f);
  weave.write_exr(dir / "weave.exr");
  nlohmann::json d = nlohmann::json::parse(slurp(kExamples / "lambert-plane.json"));
  d["gltf"] = (kExamples / "lambert-plane.gltf").string();
  d["materials"]["plane"] = {{"type", "fabric_table"},
                             {"params", {{"file", "fabric.exr"}, {"weave", "weave.exr"}}}};
  d.erase("sweep");
  std::ofstream(dir / "woven.json") << d.dump(2);
  const CliRun near = run_weft_cli("render '" + (dir / "woven.json").string() +
                                       "' --width 24 --height 20 --spp 1 --quiet --json -o '" +
                                       (dir / "out.exr").string() + "'",
                                   dir);
  ASSERT_EQ(near.exit_code, 0) << near.err;
  const nlohmann::json j = nlohmann::json::parse(near.out);
  ASSERT_EQ(j["weave_levels"].size(), 1u) << near.out;
  EXPECT_EQ(j["weave_levels"][0]["object"], "plane");
  EXPECT_EQ(j["weave_levels"][0]["level"], "weave");
  EXPECT_EQ(j["weave_levels"][0]["setting"], "auto");
  EXPECT_GE(j["weave_levels"][0]["repeat_pixels"].get<double>(), 9.0);  // 0.5 m at <= 5 cm a px
  const CliRun strict = run_weft_cli("render '" + (dir / "woven.json").string() +
                                         "' --width 24 --height 20 --spp 1 --quiet --json -o '" +
                                         (dir / "out.exr").string() +
                                         "' -D materials.plane.params.weave_min_pixels=1000",
                                     dir);
  ASSERT_EQ(strict.exit_code, 0) << strict.err;
  EXPECT_EQ(nlohmann::json::parse(strict.out)["weave_levels"][0]["level"], "table");
}
