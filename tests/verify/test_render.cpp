// The renders of weft verify's report (verify/render.h, verify_render.cpp): the patch's radiance
// against its table, the fiber-level renders against the fabric ray trace.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/registry.h"
#include "weft/verify/verify.h"

namespace fs = std::filesystem;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace weft {
namespace {

// The renders (paper's Figs. 8-9): a flat patch under a parallel light of irradiance pi has the
// radiance L = f E |cos theta_i| = pi f (lights.h: a parallel light's value is the irradiance on
// a plane facing it; the light is at normal incidence). So the patch's pixels must be pi times
// the table interpolated (TabulatedBsdfTable::interpolate, "like the table material does") at the
// camera's direction (zenith 30 deg, azimuth 180 deg: local (-1/2, 0, sqrt(3)/2), the patch's
// tangent being x) and the light's (+z in reflection, -z in transmission). The table differs in
// each channel, between reflection and transmission, and with wo.x (so a wrong side, azimuth or
// light direction fails). Tolerance 1e-4 relative: float pixels and table, nothing random (one
// light, nothing else in the scene, every camera ray of an orthographic camera parallel).
double channel(const Rgb& c, int k) {
  return k == 0 ? c.r : k == 1 ? c.g : c.b;
}

TEST(VerifyRender, PatchRadianceIsPiTimesTheTableForEachConfiguration) {
  const fs::path dir = fresh_test_dir();
  auto f = [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const bool same_side = (wo.z > 0) == (wi.z > 0);
    const double a = 1 + 0.8 * wo.x;
    v[0] = (same_side ? 0.30 : 0.05) * a;
    v[1] = (same_side ? 0.04 : 0.10) * a;
    v[2] = (same_side ? 0.02 : 0.20) * a;
  };
  TabulatedBsdfTable t = TabulatedBsdfTable::from_function(4, 3, f, 4, 1);
  t.kind = "fabric";
  VerifyReport r;
  r.settings = verify_settings(VerifyQuality::kDraft);
  r.settings.render_size = 24;
  r.settings.render_spp = 1;
  r.computed_fabric = t;
  r.measured_nbrdf =
      fs::path(WEFT_SOURCE_DIR) / "materials/data/measured/merl-red-fabric" / "nbrdf_weights.txt";
  const std::vector<VerifyRender> renders = render_verify_samples(dir, r);
  ASSERT_EQ(renders.size(), 3u);  // computed in both configurations, measured in reflection
  EXPECT_TRUE(fs::exists(dir / "fabric-computed.exr"));
  const double s = std::sin(kVerifyRenderViewZenithDeg * std::numbers::pi / 180);
  const Vec3 wo{-s, 0, std::sqrt(1 - s * s)};
  for (const VerifyRender& v : renders) {
    const bool transmission = v.configuration == "transmission";
    Rgb want;
    if (v.model == "computed") {
      double e[3];
      t.interpolate(wo, {0, 0, transmission ? -1.0 : 1.0}, e);
      want = Rgb(e[0], e[1], e[2]) * kVerifyRenderIrradiance;
    } else {
      ASSERT_EQ(v.model, "measured");
      MaterialContext ctx;
      const Bsdf m = make_bsdf("measured_nbrdf", {{"file", r.measured_nbrdf.string()}}, ctx);
      want = m.eval(wo, {0, 0, 1}) * kVerifyRenderIrradiance;
    }
    ASSERT_EQ(v.image.width, 24);
    for (int y = 6; y < 18; ++y)
      for (int x = 6; x < 18; ++x)
        for (int k = 0; k < 3; ++k)
          ASSERT_NEAR(channel(v.image.at(x, y), k), channel(want, k), 1e-4 * channel(want, k))
              << v.stem << " pixel " << x << "," << y << " channel " << k;
    EXPECT_NEAR(v.patch_radiance.r, want.r, 1e-4 * want.r) << v.stem;
  }
  // Light from behind shows the transmission colour: blue over red here, red over blue in front.
  EXPECT_GT(renders[1].patch_radiance.b, renders[1].patch_radiance.r);
  EXPECT_GT(renders[0].patch_radiance.r, renders[0].patch_radiance.b);
}

// ---- The fiber-level renders ------------------------------------------------------------------

WovenSample poplin_at_fiber_detail() {
  WeaveOptions w;
  w.detail = "fiber";
  return make_woven_sample(overlay(red_cotton_weave_options(), w));
}

// The classic fiber of weft verify (Lambert + Cook-Torrance, opaque) with a red-brown diffuse
// colour: smooth, so its tables interpolate well at a small resolution.
TabulatedBsdfTable brown_classic_fiber() {
  return classic_fiber_table(Rgb(0.6, 0.3, 0.1), {MicrofacetModel::kBeckmann, 0.35}, 1.557, 4, 2, 1,
                             0);
}

// Only the fiber-level renders: a report holding the sample and a computed fiber table.
VerifyReport weave_report(const TabulatedBsdfTable& fiber, int size, int spp) {
  VerifyReport r;
  r.settings = verify_settings(VerifyQuality::kDraft);
  r.settings.weave_render_size = size;
  r.settings.weave_render_spp = spp;
  r.sample = std::make_shared<const WovenSample>(poplin_at_fiber_detail());
  r.computed_fiber = fiber;
  return r;
}

// Over the pixels of one channel of two renders that differ only in their seed: the variance of
// the image itself, without its noise (the covariance of the two: their noises are independent),
// and the Monte Carlo noise variance of one render's pixel (the mean of (a - b)^2 / 2).
struct PixelStats {
  double structure_variance = 0, noise_variance = 0;
};
PixelStats pixel_stats(const Image& a, const Image& b, int k) {
  const double n = static_cast<double>(a.width) * a.height;
  double ma = 0, mb = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      ma += channel(a.at(x, y), k) / n;
      mb += channel(b.at(x, y), k) / n;
    }
  PixelStats s;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const double va = channel(a.at(x, y), k), vb = channel(b.at(x, y), k);
      s.structure_variance += (va - ma) * (vb - mb) / n;
      s.noise_variance += (va - vb) * (va - vb) / 2 / n;
    }
  return s;
}

// The fiber-level render shows the weave: its film is whole repeats of the poplin (3 across the
// warps, 0.4234 mm each: 1.270 mm wide; 2 along them, 0.8466 mm foreshortened by cos 30 deg:
// 1.466 mm tall, so 42 x 48 pixels at size 48), and the image varies across the frame far more
// than its noise does. A render of one colour (a flat patch, or fibers all lit alike) has no
// structure variance, so this fails for it: the covariance of two seeds' images is then zero up to
// its sampling error (about the noise variance / sqrt(pixels), 3 % of it at 28 x 32 pixels).
// Measured at 64 spp, red: structure 23 (reflection) and 3.4 (transmission, lit only through
// the cloth) times the noise. And the same bits at any thread count.
TEST(VerifyWeaveRender, ShowsTheWeaveAboveItsNoiseAtAnyThreadCount) {
  const fs::path dir = fresh_test_dir();
  const VerifyWeaveFrame f = verify_weave_frame(poplin_at_fiber_detail().summary, 48);
  EXPECT_EQ(f.repeats_z, 3);
  EXPECT_EQ(f.repeats_x, 2);
  EXPECT_NEAR(f.half_width_m, 1.5 * 0.4234e-3, 1e-9);
  EXPECT_NEAR(f.half_height_m, 0.8466e-3 * std::sqrt(3.0) / 2, 1e-9);
  EXPECT_EQ(f.width, 42);
  EXPECT_EQ(f.height, 48);
  EXPECT_NE(error_of([] { verify_weave_frame(WeaveSummary{}, 48); }).find("period"),
            std::string::npos);

  VerifyReport r = weave_report(brown_classic_fiber(), 32, 64);
  r.settings.threads = 1;
  const std::vector<VerifyRender> a = render_verify_samples(dir, r);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_TRUE(fs::exists(dir / "fiber-computed.exr"));
  r.settings.threads = 2;
  const std::vector<VerifyRender> same = render_verify_samples(dir, r);
  r.settings.seed = 2;
  const std::vector<VerifyRender> b = render_verify_samples(dir, r);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].kind, "weave");
    EXPECT_EQ(a[i].stem,
              std::string("render-weave-") + (i ? "transmission" : "reflection") + "-computed");
    ASSERT_EQ(a[i].image.width, 28);
    ASSERT_EQ(a[i].image.height, 32);
    EXPECT_TRUE(a[i].image.rgb == same[i].image.rgb) << a[i].stem;
    const PixelStats s = pixel_stats(a[i].image, b[i].image, 0);
    EXPECT_GT(s.structure_variance, (i ? 1.5 : 10.0) * s.noise_variance)
        << a[i].stem << ": noise variance " << s.noise_variance;
  }
}

// Over whole repeats the film's mean is the cloth's mean radiance for the view and the light,
// which the fiber-level ray trace of the same sample and fiber table estimates as a fabric table
// (fabric_raytrace.h): pi f_fabric(30 deg view, normal light) in reflection. Two estimators of
// one transport, each shading a fiber with the whole-fiber table; the opaque classic fiber's cloth
// has a smooth BRDF, so the table's cells (R = 4) average little away. Tolerance: 3 standard
// errors of the ray trace's value, taken as its relative noise per cell (5 % here, the value
// interpolates between several cells) times 1.5, plus the render's, about 0.5 % at 16 spp over
// the whole film. Measured: within 1.7 % in every channel. In transmission the table holds the
// light that passes straight through the gaps, spread over the cell around the beam's direction,
// which no camera off that direction sees: the table's pi f is 0.15 there, the render 0.011.
TEST(VerifyWeaveRender, MeanOverWholeRepeatsIsTheFabricRayTracesValueInReflection) {
  const fs::path dir = fresh_test_dir();
  const TabulatedBsdfTable fiber = brown_classic_fiber();
  const VerifyReport r = weave_report(fiber, 48, 16);
  FabricRaytraceOptions o;
  o.resolution = 4;
  o.particles_per_bin = 8000;
  const FabricRaytraceResult traced = raytrace_fabric_table(*r.sample, fiber, o);
  const double sv = std::sin(kVerifyRenderViewZenithDeg * std::numbers::pi / 180);
  double e[3];
  traced.table.interpolate({-sv, 0, std::sqrt(1 - sv * sv)}, {0, 0, 1}, e);
  const Rgb want = Rgb(e[0], e[1], e[2]) * kVerifyRenderIrradiance;
  const std::vector<VerifyRender> renders = render_verify_samples(dir, r);
  ASSERT_EQ(renders.size(), 2u);
  const double tolerance = 1.5 * traced.relative_noise + 0.005;
  ASSERT_LT(tolerance, 0.1);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(channel(renders[0].mean, k), channel(want, k), tolerance * channel(want, k))
        << "channel " << k;
  // In transmission the cloth of opaque fibers shows only light they scatter off the beam.
  EXPECT_LT(renders[1].mean.r, 0.2 * renders[0].mean.r);
}

// A spectral fiber table is rendered band by band (RenderSettings::spectral), as the ray trace
// traces it: opaque fibers that reflect diffusely 0.9 of the light in the bands from 590 nm and
// 0.2 below pass red light between them, and multiple scattering does not commute with the
// reduction to RGB (the reduced table's red albedo is 0.99). The fiber-level render of the
// spectral table agrees with the spectral ray trace (tolerance as in the test above, from the
// trace's own noise); the RGB transport of the reduced table is redder. Measured (48 px, 16 spp,
// 8 000 particles per bin; tolerance 8.2 %): spectral render against trace +1.1, +5.0, +5.8 % in R,
// G, B; the RGB render's red 1.068 times the spectral render's (the renders' noise about 0.5 %).
// At 64 000 particles the trace's red is 12 % below its RGB trace's, and green and blue render
// 6 % above the trace in RGB as in bands (R = 4 cells, not the spectral transport).
TEST(VerifyWeaveRender, SpectralFiberTableRendersAsItsSpectralRayTrace) {
  const fs::path dir = fresh_test_dir();
  TabulatedBsdfTable fiber = TabulatedBsdfTable::from_function(
      4, kNumBands,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const bool lit = wo.z > 0 && wi.z > 0;  // an opaque fiber, as the classic one
        for (int b = 0; b < kNumBands; ++b)
          v[b] = lit ? (b >= 20 ? 0.9 : 0.2) / std::numbers::pi : 0;
      },
      2, 1);
  fiber.kind = "fiber";
  const VerifyReport r = weave_report(fiber, 48, 16);
  FabricRaytraceOptions o;
  o.resolution = 4;
  o.particles_per_bin = 8000;
  const FabricRaytraceResult traced = raytrace_fabric_table(*r.sample, fiber, o);
  const TabulatedBsdfTable rgb_fabric = table_to_rgb(traced.table);
  const double sv = std::sin(kVerifyRenderViewZenithDeg * std::numbers::pi / 180);
  double e[3];
  rgb_fabric.interpolate({-sv, 0, std::sqrt(1 - sv * sv)}, {0, 0, 1}, e);
  const Rgb want = Rgb(e[0], e[1], e[2]) * kVerifyRenderIrradiance;
  const std::vector<VerifyRender> renders = render_verify_samples(dir, r);
  ASSERT_EQ(renders.size(), 2u);
  EXPECT_NE(renders[0].caption.find("33 bands"), std::string::npos) << renders[0].caption;
  EXPECT_EQ(TabulatedBsdfTable::read_exr(dir / "fiber-computed.exr").channels, kNumBands);
  const double tolerance = 1.5 * traced.relative_noise + 0.005;
  ASSERT_LT(tolerance, 0.1);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(channel(renders[0].mean, k), channel(want, k), tolerance * channel(want, k))
        << "channel " << k;
  // The RGB transport of the same table reduced to RGB.
  const std::vector<VerifyRender> rgb =
      render_verify_samples(dir, weave_report(table_to_rgb(fiber), 48, 16));
  ASSERT_EQ(rgb.size(), 2u);
  EXPECT_GT(rgb[0].mean.r, 1.04 * renders[0].mean.r);
}

// The configurations light the fibers as their names say: a fiber table that is red for light on
// the viewer's side of the fiber's surface (same side) and blue for light through the fiber from
// behind (other side) makes the cloth red in reflection and blue in transmission. Light from the
// wrong side, or a wrong table, fails. Measured (16 spp): reflection R/B 2.0, transmission B/R 2.2.
TEST(VerifyWeaveRender, ColourFollowsTheFiberTablesReflectionAndTransmission) {
  const fs::path dir = fresh_test_dir();
  auto f = [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const bool same_side = (wo.z > 0) == (wi.z > 0);
    v[0] = same_side ? 0.12 : 0.05;
    v[1] = 0.08;
    v[2] = same_side ? 0.05 : 0.12;
  };
  TabulatedBsdfTable t = TabulatedBsdfTable::from_function(4, 3, f, 2, 1);
  t.kind = "fiber";
  const std::vector<VerifyRender> renders = render_verify_samples(dir, weave_report(t, 32, 16));
  ASSERT_EQ(renders.size(), 2u);
  EXPECT_GT(renders[0].mean.r, 1.5 * renders[0].mean.b) << renders[0].stem;
  EXPECT_GT(renders[1].mean.b, 1.5 * renders[1].mean.r) << renders[1].stem;
  // A report without the sample (yarn detail, or a library caller's) has no fiber-level render.
  VerifyReport none = weave_report(t, 32, 16);
  none.sample.reset();
  EXPECT_TRUE(render_verify_samples(dir, none).empty());
}

}  // namespace
}  // namespace weft
