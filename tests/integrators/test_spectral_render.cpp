// Spectral renders (RenderSettings::spectral, path_tracer.h): light carried per band, reduced to
// linear sRGB after.
//  * Single scattering is linear in f, so a spectral render of a spectral table equals the RGB
//    render of the table reduced to RGB (in gamut), pixel by pixel (a path carries every band and
//    draws its directions as in RGB).
//  * Inside a closed enclosure whose walls emit Le and reflect diffusely with albedo rho, the
//    radiance is Le / (1 - rho) (test_furnace.cpp); with a band-dependent rho it is that per band,
//    and the image is its D65 reduction, not Le / (1 - rho reduced): the case the RGB transport
//    gets wrong.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_settings.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
using nlohmann::json;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace {

// A red diffuser's albedo per band: 0.1 below 590 nm, 0.8 from 590 nm (band 20) up.
double red_albedo(int band) {
  return band >= 20 ? 0.8 : 0.1;
}

// A two-sided diffuser of albedo a(band) per band (33 channels), or the same reduced to RGB.
TabulatedBsdfTable diffuser(bool spectral) {
  const int channels = spectral ? kNumBands : 3;
  return TabulatedBsdfTable::from_function(
      4, channels,
      [spectral](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const bool reflect = wo.z * wi.z > 0;
        if (spectral) {
          for (int b = 0; b < kNumBands; ++b) v[b] = reflect ? red_albedo(b) / kPi : 0.0;
        } else {
          const Rgb a = bands_to_linear_srgb(red_albedo);
          v[0] = reflect ? a.r / kPi : 0, v[1] = reflect ? a.g / kPi : 0,
          v[2] = reflect ? a.b / kPi : 0;
        }
      },
      4, 1);
}

// A table whose value differs by band and direction: single scattering off it tells every band's
// weight apart.
TabulatedBsdfTable patterned(int channels) {
  return TabulatedBsdfTable::from_function(
      6, channels,
      [channels](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        for (int c = 0; c < channels; ++c)
          v[c] = (0.05 + 0.02 * c * c / channels + 0.1 * std::abs(wo.z) * (1 + wi.x)) *
                 (wo.z * wi.z > 0 ? 1.0 : 0.3);
      },
      4, 1);
}

// The enclosure of test_furnace.cpp: a faceted unit sphere, normals inward, of 'material'.
SceneDescription enclosure(const json& material) {
  const json j = {{"objects",
                   {{{"type", "sphere"},
                     {"name", "room"},
                     {"material", "wall"},
                     {"center", {0, 0, 0}},
                     {"radius", 1.0},
                     {"subdivisions", 2},
                     {"inward", true},
                     {"smooth", false}}}},
                  {"materials", {{"wall", material}}},
                  {"camera",
                   {{"type", "perspective"},
                    {"position", {0.1, -0.2, 0.3}},
                    {"look_at", {1, 0, 0}},
                    {"up", {0, 1, 0}}}}};
  return parse_scene_description(j, ".", "enclosure.json");
}

// A unit quad of 'material' under parallel light at normal incidence, seen at 30 deg ('lights'
// replaces the light when given).
SceneDescription patch(const json& material, const json& light_irradiance = 1.0,
                       const json& lights = nullptr) {
  json j = {{"objects",
             {{{"type", "quad"},
               {"name", "cloth"},
               {"material", "cloth"},
               {"center", {0, 0, 0}},
               {"normal", {0, 1, 0}},
               {"tangent", {1, 0, 0}},
               {"size", {1, 1}}}}},
            {"materials", {{"cloth", material}}},
            {"lights",
             {{{"type", "parallel"},
               {"irradiance", light_irradiance},
               {"zenith_deg", 0.0},
               {"azimuth_deg", 0.0}}}},
            {"camera",
             {{"type", "orthographic"},
              {"frame_object", "cloth"},
              {"zenith_deg", 30.0},
              {"azimuth_deg", 180.0}}}};
  if (!lights.is_null()) j["lights"] = lights;
  return parse_scene_description(j, ".", "patch.json");
}

double mean_channel(const Image& im, int c) {
  double s = 0;
  for (size_t i = c; i < im.rgb.size(); i += 3) s += im.rgb[i];
  return s / (im.rgb.size() / 3);
}

}  // namespace

TEST(SpectralRender, SingleScatteringEqualsTheRgbRenderOfTheReducedTable) {
  const auto dir = fresh_test_dir();
  const TabulatedBsdfTable spectral = patterned(kNumBands);
  // The same table reduced to RGB (the values are positive and smooth in band: in gamut).
  TabulatedBsdfTable rgb = spectral;
  rgb.channels = 3;
  rgb.values.clear();
  for (size_t cell = 0; cell < spectral.values.size() / kNumBands; ++cell) {
    const float* v = &spectral.values[cell * kNumBands];
    const Rgb c = bands_to_linear_srgb([v](int b) { return v[b]; });
    ASSERT_GT(std::min({c.r, c.g, c.b}), 0);
    rgb.values.insert(rgb.values.end(), {float(c.r), float(c.g), float(c.b)});
  }
  spectral.write_exr(dir / "spectral.exr");
  rgb.write_exr(dir / "rgb.exr");
  RenderSettings s;
  s.width = s.height = 8;
  s.spp = 3;
  s.seed = 5;
  const SceneDescription a =
      patch({{"type", "fiber_table"}, {"params", {{"file", (dir / "spectral.exr").string()}}}});
  const SceneDescription b =
      patch({{"type", "fiber_table"}, {"params", {{"file", (dir / "rgb.exr").string()}}}});
  RenderSettings ss = s;
  ss.spectral = true;
  const RenderResult ra = render(RenderScene(a), *a.camera, ss);
  const RenderResult rb = render(RenderScene(b), *b.camera, s);
  ASSERT_EQ(ra.image.rgb.size(), rb.image.rgb.size());
  double largest = 0;
  for (size_t i = 0; i < ra.image.rgb.size(); ++i) {
    ASSERT_GT(rb.image.rgb[i], 0.01f);
    largest = std::max(largest, std::abs(ra.image.rgb[i] / rb.image.rgb[i] - 1.0));
  }
  // float table values and float pixels: 1e-5.
  EXPECT_LT(largest, 1e-5);
  // The same table read in RGB (its reduction at load) renders the same image too.
  const RenderResult rc = render(RenderScene(a), *a.camera, s);
  for (size_t i = 0; i < rc.image.rgb.size(); ++i)
    EXPECT_NEAR(rc.image.rgb[i] / rb.image.rgb[i], 1.0, 1e-5);
  // The same bits at any thread count.
  ss.threads = 1;
  const RenderResult one = render(RenderScene(a), *a.camera, ss);
  ss.threads = 2;
  const RenderResult two = render(RenderScene(a), *a.camera, ss);
  EXPECT_EQ(one.image.rgb, two.image.rgb);
}

TEST(SpectralRender, EmittingEnclosureReachesLeOverOneMinusAlbedoInEveryBand) {
  const auto dir = fresh_test_dir();
  diffuser(true).write_exr(dir / "spectral.exr");
  diffuser(false).write_exr(dir / "rgb.exr");
  const double le = 0.5;
  // Per band Le / (1 - a_b), reduced after; and what the RGB transport gives, Le / (1 - a_c) with
  // a_c the reduced albedo, per channel.
  const Rgb expected = bands_to_linear_srgb([&](int b) { return le / (1 - red_albedo(b)); });
  const Rgb a_rgb = bands_to_linear_srgb(red_albedo);
  ASSERT_LT(a_rgb.max_component(), 1);
  const Rgb rgb_transport(le / (1 - a_rgb.r), le / (1 - a_rgb.g), le / (1 - a_rgb.b));
  // They differ by far more than the test's noise (red: 2.76 against 4.69, whose reduced albedo
  // is 0.89).
  ASSERT_GT(std::abs(rgb_transport.r / expected.r - 1), 0.1);

  RenderSettings s;
  s.width = s.height = 24;
  s.spp = 16;
  s.max_depth = 200;
  s.seed = 3;
  s.spectral = true;
  for (const char* file : {"spectral.exr", "rgb.exr"}) {
    SCOPED_TRACE(file);
    const SceneDescription d = enclosure(
        {{"type", "fiber_table"}, {"params", {{"file", (dir / file).string()}}}, {"emission", le}});
    const bool spectral = std::string(file) == "spectral.exr";
    s.spectral = spectral;
    const RenderResult r = render(RenderScene(d), *d.camera, s);
    const Rgb want = spectral ? expected : rgb_transport;
    for (int c = 0; c < 3; ++c) {
      // The standard error from the pixels' spread (each pixel the mean of its samples).
      const double m = mean_channel(r.image, c);
      double var = 0;
      const size_t n = r.image.rgb.size() / 3;
      for (size_t i = c; i < r.image.rgb.size(); i += 3)
        var += (r.image.rgb[i] - m) * (r.image.rgb[i] - m);
      const double se = std::sqrt(var / (n - 1) / n);
      const double w = want[c];
      EXPECT_LT(se, 0.02 * std::abs(w)) << c;  // the check below can fail
      EXPECT_NEAR(m, w, 4 * se) << c;
    }
  }
}

TEST(SpectralRender, RefusesMaterialsAndLightsWithoutASpectrum) {
  const auto dir = fresh_test_dir();
  patterned(kNumBands).write_exr(dir / "spectral.exr");
  patterned(3).write_exr(dir / "rgb.exr");
  RenderSettings s;
  s.width = s.height = 2;
  s.spp = 1;
  s.spectral = true;
  auto refusal = [&](const SceneDescription& d) {
    return error_of([&] { render(RenderScene(d), *d.camera, s); });
  };
  const json spectral_table = {{"type", "fiber_table"},
                               {"params", {{"file", (dir / "spectral.exr").string()}}}};
  // Accepted: a spectral table, grey parametric materials, a grey light.
  EXPECT_EQ(refusal(patch(spectral_table)), "");
  EXPECT_EQ(refusal(patch({{"type", "lambert"}, {"params", {{"reflectance", 0.4}}}})), "");
  EXPECT_EQ(refusal(patch({{"type", "cook_torrance"}, {"params", json::object()}})), "");
  // Refused, naming the material or the lights.
  const std::string rgb_table =
      refusal(patch({{"type", "fiber_table"}, {"params", {{"file", (dir / "rgb.exr").string()}}}}));
  EXPECT_NE(rgb_table.find("patch.json"), std::string::npos) << rgb_table;
  EXPECT_NE(rgb_table.find("materials.cloth"), std::string::npos) << rgb_table;
  EXPECT_NE(rgb_table.find("RGB table"), std::string::npos) << rgb_table;
  const std::string coloured =
      refusal(patch({{"type", "lambert"}, {"params", {{"reflectance", {0.5, 0.2, 0.1}}}}}));
  EXPECT_NE(coloured.find("materials.cloth"), std::string::npos) << coloured;
  EXPECT_NE(coloured.find("lambert"), std::string::npos) << coloured;
  const std::string tinted = refusal(
      patch({{"type", "fiber_table"},
             {"params", {{"file", (dir / "spectral.exr").string()}, {"tint", {1.0, 0.5, 0.5}}}}}));
  EXPECT_NE(tinted.find("tint"), std::string::npos) << tinted;
  const std::string light = refusal(patch(spectral_table, {1.0, 0.9, 0.9}));
  EXPECT_NE(light.find("lights"), std::string::npos) << light;
  EXPECT_NE(light.find("parallel"), std::string::npos) << light;
  // A CIE clear sky of a grey zenith radiance is grey everywhere; of a coloured one, refused.
  for (const json& zenith : {json(1.0), json({1.0, 1.0, 1.2})}) {
    const json sky = {{{"type", "sky"},
                       {"zenith_radiance", zenith},
                       {"sun_zenith_deg", 40.0},
                       {"sun_azimuth_deg", 0.0},
                       {"resolution", {32, 16}}}};
    const std::string e = refusal(patch(spectral_table, 1.0, sky));
    if (zenith.is_number()) {
      EXPECT_EQ(e, "");
    } else {
      EXPECT_NE(e.find("environment map"), std::string::npos) << e;
    }
  }
  // The same scenes render in RGB.
  s.spectral = false;
  EXPECT_EQ(refusal(patch(spectral_table, {1.0, 0.9, 0.9})), "");
}

TEST(SpectralRender, IsASettingOfTheDescription) {
  SceneDescription d = patch({{"type", "lambert"}, {"params", json::object()}});
  d.render = json{{"spectral", true}};
  EXPECT_TRUE(render_settings_from(d).spectral);
  d.render = json::object();
  EXPECT_FALSE(render_settings_from(d).spectral);
  d.render = json{{"spectral", 1}};
  const std::string e = error_of([&] { render_settings_from(d); });
  EXPECT_NE(e.find("render.spectral"), std::string::npos) << e;
}
