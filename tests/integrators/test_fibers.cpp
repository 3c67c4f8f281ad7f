// Fibers in the path tracer (path_tracer.h): a fiber is shaded with the BSDF of the whole fiber,
// without occlusion by its own fiber.
//  * One fiber under parallel light (irradiance E), seen by an orthographic camera: the pixel sum
//    times the pixel area is the radiant intensity I(w_o) of the fiber length l in view, and
//    I / (E l) = R F(w_i, w_o), F the fiber's scattering per unit length in fiber radii
//    (docs/fiber-bsdf.md): F = integral over the circumference angle of f |cos theta_i| cos+
//    theta_o.
//    - A Lambertian fiber has the closed form F = (rho / pi) sqrt(1 - s_i^2) sqrt(1 - s_o^2)
//      ((pi - a) cos a + sin a) / 2 (s: axial cosines, a: the azimuth between the directions
//      about the axis; the integral of cos+ (phi) cos+ (phi - a) over phi).
//    - A baked fiber table closes the loop baker -> renderer: the render averaged over a far-field
//      bin equals the baker's far-field tally of the same photons (fiber_bake.h).
//  * White furnace: a lossless fiber-level woven patch in a uniform environment of radiance 1
//    renders radiance 1 (R + T = 1 at every fiber, and every fiber sees radiance 1 around it).
//  * Own-fiber exclusion: light from behind a fiber reaches its far side through the fiber, but
//    not through another fiber.
//  * Bit-identical renders of a fiber scene at 1 and 2 threads (curves and tubes).
//  * The gonioreflectometer's sample and white reference cover fibers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/fiber/fiber_bake.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/integrators/fiber_scattering.h"
#include "weft/integrators/gonio.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kRadius = 8e-6;  // metres, as the weave generator's cotton

// A unit direction by its axial cosine s and azimuth psi about the fiber axis x, psi measured
// from y towards z (the baker's world frame: psi = atan2(z, y), docs/fiber-bsdf.md).
Vec3 fiber_direction(double s, double psi) {
  return weft::fiber_direction({1, 0, 0}, {0, 1, 0}, s, psi);
}

// One straight fiber along x through the origin, 200 radii long (8 segments), material "fiber".
SceneDescription one_fiber(const MaterialBinding& material, const char* geometry = "curves") {
  const double half = 100 * kRadius;
  const json j = {{"objects",
                   {{{"type", "fiber"},
                     {"name", "fiber"},
                     {"material", "fiber"},
                     {"from", {-half, 0, 0}},
                     {"to", {half, 0, 0}},
                     {"radius", kRadius},
                     {"segments", 8}}}},
                  {"materials", {{"fiber", {{"type", "lambert"}}}}},
                  {"fiber_geometry", {{"type", geometry}}}};
  SceneDescription d = parse_scene_description(j, ".", "one-fiber.json");
  d.materials["fiber"] = material;
  return d;
}

using Estimate = FiberScatteringEstimate;

// F(w_i, w_o) of the fiber of one_fiber() (fiber_scattering.h: a film of 16 x 2.5 radii).
Estimate render_f(const RenderScene& scene, const Vec3& wi, const Vec3& wo, uint64_t seed,
                  int spp = 16) {
  FiberScatteringSetup f;
  f.radius = kRadius;
  f.spp = spp;
  f.seed = seed;
  return render_fiber_scattering(scene, f, wi, wo);
}

MaterialBinding table_binding(const fs::path& file) {
  MaterialBinding b;
  b.type = "fiber_table";
  b.params = {{"file", file.string()}};
  b.field = "materials.fiber";
  return b;
}

// A one-band fiber table (the same value in R, G and B) from a baked band.
fs::path write_band_table(const FiberBandTable& band, const fs::path& file) {
  TabulatedBsdfTable table;
  table.resolution = band.resolution;
  table.kind = "fiber";
  table.values.reserve(3 * band.f.size());
  for (double f : band.f)
    for (int c = 0; c < 3; ++c) table.values.push_back(static_cast<float>(f));
  table.write_exr(file);
  return file;
}

// A lossless, isotropic fiber: f = 1 / (2 pi) over the whole sphere of both directions, so
// int f |cos theta_i| d w_i = 1 for every view (its cell averages are that constant exactly).
fs::path write_white_table(const fs::path& file) {
  TabulatedBsdfTable table;
  table.resolution = 4;
  table.kind = "fiber";
  table.values.assign(3 * size_t(table.bins()) * table.bins(), static_cast<float>(0.5 * kInvPi));
  table.write_exr(file);
  return file;
}

}  // namespace

TEST(Fibers, LambertFiberRendersTheClosedForm) {
  // The classical diffuse cylinder: with own-fiber exclusion every point of the fiber sees the
  // light, and lambert (two-sided reflection) returns nothing from the unlit side, so the render
  // must match the closed form for any pair of directions. Checks the fiber's geometry, its
  // normals, the film's length and the factor R.
  const double rho = 0.7;
  MaterialBinding lambert;
  lambert.type = "lambert";
  lambert.params = {{"reflectance", rho}};
  const RenderScene scene(one_fiber(lambert));
  struct Case {
    double s_i, s_o, dpsi_deg;
  };
  for (const Case c : {Case{0, 0, 0}, Case{0, 0, 90}, Case{0.3, -0.5, 40}, Case{-0.6, 0.2, 130},
                       Case{0.5, 0.5, -100}, Case{0.1, 0.7, 120}}) {
    SCOPED_TRACE(::testing::Message()
                 << "s_i " << c.s_i << " s_o " << c.s_o << " dpsi " << c.dpsi_deg);
    const double psi_i = 0.7;  // any: the fiber is round
    const double a = deg_to_rad(std::abs(c.dpsi_deg));
    const double expected = rho * kInvPi * std::sqrt(1 - c.s_i * c.s_i) *
                            std::sqrt(1 - c.s_o * c.s_o) * 0.5 *
                            ((kPi - a) * std::cos(a) + std::sin(a));
    const Estimate f = render_f(scene, fiber_direction(c.s_i, psi_i),
                                fiber_direction(c.s_o, psi_i + deg_to_rad(c.dpsi_deg)), 3, 256);
    EXPECT_LT(f.std_error, 0.01 * expected);
    EXPECT_NEAR(f.value, expected, 4 * f.std_error);
  }
}

TEST(Fibers, OneFiberRenderOfABakedTableMatchesTheBakersFarFieldTally) {
  // The loop baker -> renderer. Each of kBakes independent direct-route bakes of one band gives a
  // fiber table and the far-field tally of the same photons. The tally (fiber_bake.cpp) adds
  // pi w / N per exit, with s_i drawn with density (2/pi) sqrt(1 - s_i^2) and the impact
  // parameter uniformly, i.e. per unit of the flux E 2 R l sqrt(1 - s_i^2) that hits a length l:
  // its expectation is the integral of F = I / (E l R) over the bin in (s_i, s_o, dpsi), so the
  // bin average of F is tally / (ds ds dpsi). The render of the table (render_f), averaged over
  // direction pairs drawn uniformly (Latin hypercube) within the bin, estimates the same average.
  // Per bake, render - tally carries every noise (photons of table and tally and their
  // correlation, pixels, directions); over the bakes its mean must vanish within 4 standard
  // errors.
  //
  // What the table's discretisation leaves (measured with this test's settings, 8 x 250 000
  // photons): f = L_o / (E |cos theta_i|) grows as 1 / |cos theta_i| towards the incident horizon
  // (light entering elsewhere still leaves near the terminator), and bilinear interpolation of
  // its cell averages overestimates f |cos theta_i| there, most where the light's circle of
  // local directions meets the horizon head-on. In the bins of near-perpendicular light
  // (|s_i| < 0.2, the far field's middle s bin) the render exceeds the tally by 4 to 9 % at R = 8,
  // 1.4 to 4.9 % at R = 16 and about 1 % at R = 32 (an analytic f ~ 1 / |cos theta_i| shows the
  // same); for |s_i| in [0.2, 0.6] it stays below the noise (about 1 %) at R = 16, and those are
  // the bins tested. A clear fiber (the cotton presets, mu_s R < 1) also sends its unscattered
  // light along the cone s_o = -s_i (Bravais' law), which no table resolves: there bins on or
  // beside the cone differ by 5 to 60 % at R = 16. Hence a scattering fiber here (voids, about 23
  // scattering events per photon), whose F is smooth.
  const std::string json_spec = R"({"name": "scattering", "fiber_radius_um": 8,
    "roughness": {"distribution": "ggx", "alpha": 0.5},
    "host": {"n": 1.557, "absorption_per_um": 0.005},
    "species": [{"name": "voids", "n": 1.0, "k": 0.0, "volume_fraction": 0.12,
      "size": {"distribution": "monodisperse", "radius_um": 0.3}}]})";
  const FiberSpec spec = parse_fiber_spec(json_spec, "scattering-fiber");
  const FiberBandPhysics ph = fiber_band_physics(spec, compute_medium_band(spec, 26));
  constexpr int kBakes = 8, kDirs = 16;
  constexpr int kS = 5, kPsi = 6;  // axial cosine bins of width 0.4, azimuth bins of 60 degrees
  struct Bin {
    int a, b, c;
  };
  // s bins 1 and 3: |s| in [0.2, 0.6]; c = 0 and 5: light going on through the fiber (dpsi near
  // +-180 deg), 2 and 3: back towards the light. (3, 1): on the specular cone s_o = -s_i; (3, 3)
  // and (1, 1): away from it; (1, 2), (3, 2): across it.
  const std::vector<Bin> bins = {{3, 1, 0}, {3, 1, 2}, {3, 1, 4}, {3, 3, 5}, {3, 3, 3}, {3, 2, 1},
                                 {1, 1, 0}, {1, 1, 2}, {1, 2, 5}, {1, 2, 3}, {1, 3, 4}, {1, 3, 1}};
  const double ds = 2.0 / kS, dpsi = 2 * kPi / kPsi;
  const fs::path dir = weft::testing::fresh_test_dir();
  std::vector<std::vector<double>> render(bins.size()), tally(bins.size());
  FiberBakeSettings s;
  s.resolution = 16;
  s.photons = 250000;
  s.far_field_s_bins = kS;
  s.far_field_psi_bins = kPsi;
  for (int k = 0; k < kBakes; ++k) {
    s.seed = 100 + k;
    const FiberBandTable band = bake_fiber_band_direct(ph, s, nullptr);
    ASSERT_EQ(band.far_field.size(), size_t(kS * kS * kPsi));
    const fs::path table = write_band_table(band, dir / ("band" + std::to_string(k) + ".exr"));
    const RenderScene scene(one_fiber(table_binding(table)));
    for (size_t j = 0; j < bins.size(); ++j) {
      const Bin& b = bins[j];
      tally[j].push_back(band.far_field[(size_t(b.a) * kS + b.b) * kPsi + b.c] / (ds * ds * dpsi));
      // Latin hypercube over (s_i, s_o, dpsi) within the bin; psi_i anywhere (the fiber is round).
      Rng rng(7, uint64_t(k), j);
      std::vector<int> perm_o(kDirs), perm_p(kDirs);
      for (int i = 0; i < kDirs; ++i) perm_o[i] = perm_p[i] = i;
      for (int i = kDirs - 1; i > 0; --i) {
        std::swap(perm_o[i], perm_o[std::min(i, int(rng.uniform() * (i + 1)))]);
        std::swap(perm_p[i], perm_p[std::min(i, int(rng.uniform() * (i + 1)))]);
      }
      double sum = 0;
      for (int i = 0; i < kDirs; ++i) {
        const double s_i = -1 + ds * (b.a + (i + rng.uniform()) / kDirs);
        const double s_o = -1 + ds * (b.b + (perm_o[i] + rng.uniform()) / kDirs);
        const double dp = -kPi + dpsi * (b.c + (perm_p[i] + rng.uniform()) / kDirs);
        const double psi_i = 2 * kPi * rng.uniform();
        sum += render_f(scene, fiber_direction(s_i, psi_i), fiber_direction(s_o, psi_i + dp),
                        uint64_t(1000 * k + 100 * j + i))
                   .value;
      }
      render[j].push_back(sum / kDirs);
    }
  }
  double lo = 1e300, hi = 0;
  for (size_t j = 0; j < bins.size(); ++j) {
    SCOPED_TRACE(::testing::Message()
                 << "bin (" << bins[j].a << ", " << bins[j].b << ", " << bins[j].c << ")");
    auto stats = [](const std::vector<double>& x) {
      return weft::testing::sample_mean(int(x.size()), [&](int i) { return x[i]; });
    };
    std::vector<double> diff(kBakes);
    for (int k = 0; k < kBakes; ++k) diff[k] = render[j][k] - tally[j][k];
    const auto r = stats(render[j]), t = stats(tally[j]), d = stats(diff);
    std::printf(
        "one fiber, bin (%d,%d,%d): render %.5f +- %.5f, tally %.5f +- %.5f, difference "
        "%+.5f +- %.5f (%+.2f %%)\n",
        bins[j].a, bins[j].b, bins[j].c, r.mean, r.std_error, t.mean, t.std_error, d.mean,
        d.std_error, 100 * d.mean / t.mean);
    EXPECT_LT(d.std_error, 0.02 * t.mean);  // sharp enough to see a missing factor or a lost lobe
    EXPECT_NEAR(d.mean, 0, 4 * d.std_error);
    lo = std::min(lo, t.mean), hi = std::max(hi, t.mean);
  }
  EXPECT_GT(hi, 1.3 * lo);  // the bins differ: a wrong direction convention would show
}

TEST(Fibers, LightFromBehindReachesAFiberThroughItselfButNotThroughAnother) {
  // Light from below (-y), camera above: every point the camera sees is on the fiber's unlit side.
  // With the lossless isotropic table f = 1 / (2 pi), light through the fiber's own body arrives
  // (own-fiber exclusion): F = (1 / (2 pi)) int |cos x| cos+(x - pi) dx = (1 / (2 pi)) (pi / 2)
  // = 1/4 for light and view across the axis. A second fiber in the beam below shadows it
  // completely (direct light only: F = 0); the same fiber beside the beam changes nothing.
  const fs::path table = write_white_table(weft::testing::fresh_test_dir() / "white.exr");
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    auto scene_with = [&](std::optional<Vec3> other) {
      SceneDescription d = one_fiber(table_binding(table), geometry);
      if (other) {
        FiberCurves c = *d.curves[0];
        for (size_t i = 0; i < c.point_count(); ++i)
          for (int k = 0; k < 3; ++k) c.points[4 * i + k] += static_cast<float>((*other)[k]);
        d.curves.push_back(std::make_shared<const FiberCurves>(std::move(c)));
      }
      return RenderScene(d);
    };
    const Vec3 wi{0, -1, 0}, wo{0, 1, 0};
    const Estimate alone = render_f(scene_with(std::nullopt), wi, wo, 5, 64);
    if (std::string(geometry) == "curves")
      EXPECT_NEAR(alone.value, 0.25, 4 * alone.std_error);
    else  // an octagon: its flat facets shade differently (bench/ measures by how much)
      EXPECT_GT(alone.value, 0.0);
    const Estimate shadowed = render_f(scene_with(Vec3{0, -3 * kRadius, 0}), wi, wo, 5, 64);
    EXPECT_EQ(shadowed.value, 0.0);
    const Estimate beside = render_f(scene_with(Vec3{0, -3 * kRadius, 4 * kRadius}), wi, wo, 5, 64);
    EXPECT_EQ(beside.value, alone.value);  // the same samples, unblocked
  }
}

TEST(Fibers, LightFromBehindCrossesTheJointsOfAFiberCutIntoPieces) {
  // The fiber of one_fiber() cut into 50 straight curves of 4 radii, end to end (their end
  // spheres overlap at each joint, as where a woven sample's tiles join a fiber to its
  // continuation), with the lossless isotropic table. Light from below at axial cosine 0.8 runs
  // through the fiber along chords up to 2.7 radii long, which cross a joint for many of the
  // points the camera above sees; it must still arrive: F = (1 / (2 pi)) sqrt(1 - s^2) pi / 2 =
  // sqrt(1 - s^2) / 4, as for the whole fiber. (With the next piece taken as a wall, the light
  // that crosses a joint was lost: the fiber-level renders of red cotton came out 8-14 % darker
  // than the ray-traced fabric table of the same sample.)
  const fs::path table = write_white_table(weft::testing::fresh_test_dir() / "white.exr");
  const double s = 0.8;
  const Vec3 wi = fiber_direction(s, kPi), wo{0, 1, 0};
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    json pieces = json::array();
    for (int k = 0; k < 50; ++k)
      pieces.push_back({{"type", "fiber"},
                        {"name", "piece" + std::to_string(k)},
                        {"material", "fiber"},
                        {"from", {(-100 + 4 * k) * kRadius, 0, 0}},
                        {"to", {(-96 + 4 * k) * kRadius, 0, 0}},
                        {"radius", kRadius},
                        {"segments", 1}});
    const json j = {{"objects", pieces},
                    {"materials", {{"fiber", {{"type", "lambert"}}}}},
                    {"fiber_geometry", {{"type", geometry}}}};
    SceneDescription cut = parse_scene_description(j, ".", "pieces.json");
    cut.materials["fiber"] = table_binding(table);
    const Estimate whole =
        render_f(RenderScene(one_fiber(table_binding(table), geometry)), wi, wo, 5, 64);
    const Estimate pieces_f = render_f(RenderScene(cut), wi, wo, 5, 64);
    if (std::string(geometry) == "curves") {
      EXPECT_NEAR(pieces_f.value, std::sqrt(1 - s * s) / 4, 4 * pieces_f.std_error);
    }
    EXPECT_NEAR(pieces_f.value, whole.value, 4 * std::hypot(whole.std_error, pieces_f.std_error));
    EXPECT_LT(pieces_f.std_error, 0.01 * pieces_f.value);
  }
}

namespace {

// A fiber-level woven patch (the weave generator's red-cotton poplin, fibers as curves), every
// fiber bound to 'material', in a constant environment of radiance 'environment' and optionally
// a parallel light. At packing 0.25 (the bundled sample packs 0.55): these tests' ray counts and
// noise bounds were set for it, and a denser cloth occludes more per ray (the furnace's standard
// error at 100 000 rays grows from under 0.007 to 0.012), which is not what they check.
SceneDescription fiber_patch(const MaterialBinding& material, const char* geometry,
                             double environment, bool sun) {
  WeaveOptions sparse;
  sparse.packing = 0.25;
  SceneDescription d =
      fiber_patch_description(overlay(red_cotton_weave_options(), sparse), "fiber patch", "patch");
  d.materials["warp"] = d.materials["weft"] = material;
  d.fiber_geometry.type =
      std::string(geometry) == "tubes" ? FiberGeometry::Type::tubes : FiberGeometry::Type::curves;
  d.lights.environment = Rgb(environment);
  if (sun) d.lights.directional.push_back({d.frame.direction(deg_to_rad(30), 0), Rgb(2.0)});
  d.camera = frame_box_orthographic(d.object_bounds("patch"), d.frame.direction(deg_to_rad(35), 1),
                                    d.frame.normal);
  return d;
}

}  // namespace

TEST(Fibers, LosslessFiberPatchInAWhiteFurnaceRendersOne) {
  // Every fiber scatters all the light that reaches it (int f |cos theta_i| d w_i = 1 for every
  // view: reflection + transmission = 1) and, with its own fiber excluded, every point of it sees
  // radiance 1 from every direction: the environment, or other fibers that return radiance 1.
  // So every camera ray that meets a fiber carries radiance 1, seen from above, below or the side
  // (pbrt-v4's furnace scenes for the principle). Camera rays aim at random points of the patch.
  const fs::path table = write_white_table(weft::testing::fresh_test_dir() / "white.exr");
  for (const char* geometry : {"curves", "tubes"}) {
    const SceneDescription d = fiber_patch(table_binding(table), geometry, 1.0, false);
    const RenderScene scene(d);
    const Bounds3 box = d.object_bounds("patch");
    RenderSettings s;
    // No roulette: with albedo 1 it would only add variance (weights 1 / 0.95 per bounce); a
    // lossless path ends when it leaves the cloth, long before max_depth.
    s.max_depth = 100000;
    s.rr_depth = 100000;
    s.seed = 17;
    for (double view_deg : {0.0, 70.0, 150.0}) {  // 150: from below, the cloth's back
      SCOPED_TRACE(::testing::Message() << geometry << ", view " << view_deg << " deg");
      const Vec3 to_viewer = d.frame.direction(deg_to_rad(view_deg), 0.4);
      RayCounts rays;
      const int n = 100000;
      std::vector<double> on_fibers;  // radiance of the camera rays that meet a fiber
      for (int i = 0; i < n; ++i) {
        Rng rng(s.seed, uint64_t(view_deg), uint64_t(i));
        const Vec3 target{box.lo.x + (box.hi.x - box.lo.x) * (0.1 + 0.8 * rng.uniform()), 0,
                          box.lo.z + (box.hi.z - box.lo.z) * (0.1 + 0.8 * rng.uniform())};
        int64_t first = -1;
        const double L =
            trace_path(scene, {target + to_viewer * 1e-2, -to_viewer}, s, rng, rays, &first).g;
        if (first >= 0) on_fibers.push_back(L);
      }
      const int hits = int(on_fibers.size());
      const auto e = weft::testing::sample_mean(hits, [&](int i) { return on_fibers[i]; });
      EXPECT_GT(hits, n / 2);
      EXPECT_LT(e.std_error, 0.007);  // occlusion between fibers: about 1.5 per sample
      EXPECT_NEAR(e.mean, 1.0, 4 * e.std_error);
      std::printf("furnace, %s, view %g deg: radiance %.4f +- %.4f (%d of %d rays meet fibers)\n",
                  geometry, view_deg, e.mean, e.std_error, hits, n);
    }
  }
}

namespace {

// A small film at 3 samples per pixel.
RenderSettings small_film(int width, int height, uint64_t seed) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.spp = 3;
  s.seed = seed;
  return s;
}

}  // namespace

TEST(Fibers, FiberScenesAreBitIdenticalAtOneAndTwoThreads) {
  const fs::path table = write_white_table(weft::testing::fresh_test_dir() / "white.exr");
  MaterialBinding tinted = table_binding(table);
  tinted.params["tint"] = {0.9, 0.5, 0.4};
  for (const char* geometry : {"curves", "tubes"}) {
    SCOPED_TRACE(geometry);
    const SceneDescription d = fiber_patch(tinted, geometry, 0.3, true);
    const RenderScene scene(d);
    RenderSettings s = small_film(45, 37, 5);
    s.threads = 1;
    const RenderResult a = render(scene, *d.camera, s);
    s.threads = 2;
    const RenderResult b = render(scene, *d.camera, s);
    ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
    EXPECT_EQ(0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * 4));
    EXPECT_EQ(a.rays.total(), b.rays.total());
    double sum = 0;
    for (float v : a.image.rgb) sum += v;
    EXPECT_GT(sum, 0);
  }
}

TEST(Fibers, GonioreflectometerMeasuresAFiberPatch) {
  // The sweep's sample, framing and white reference (a material override) cover curve sets like
  // meshes. Direct light only: a patch of grey Lambertian fibers (rho = 0.4) measures exactly
  // 0.4 times its white reference, the same scene with every fiber white.
  MaterialBinding grey;
  grey.type = "lambert";
  grey.params = {{"reflectance", 0.4}};
  grey.field = "materials.fiber";
  const SceneDescription d = fiber_patch(grey, "curves", 0, false);
  GonioSettings g;
  g.sample = "patch";
  g.light_zenith_deg = 30;
  g.view_zenith_deg = {-40, 0, 40};
  g.width = g.height = 24;
  g.spp = 4;
  g.max_depth = 1;
  const GonioResult r = run_gonio(d, g);
  ASSERT_EQ(r.rows.size(), 3u);
  for (const auto& row : r.rows) {
    EXPECT_GT(row.footprint_px, 0.3 * g.width * g.height);  // the film frames the fibers
    ASSERT_TRUE(row.white.has_value());
    EXPECT_GT(row.white->g, 0.1);
    EXPECT_NEAR(row.beta.g, 0.4 * row.white->g, 1e-6 * row.white->g);
  }
  g.sample = "nothing";
  EXPECT_THROW(run_gonio(d, g), Error);
}

// Light groups (RenderSettings::light_groups): one pass over the paths gives each light's own
// image. Parallel lights draw no random numbers, so each image has the bits of a render lit by
// that light alone, and the images sum to the render's.
TEST(Fibers, LightGroupsAreEachLightsOwnRenderInOnePass) {
  const fs::path table = write_white_table(weft::testing::fresh_test_dir() / "white.exr");
  MaterialBinding tinted = table_binding(table);
  tinted.params["tint"] = {0.9, 0.5, 0.4};
  SceneDescription both = fiber_patch(tinted, "curves", 0.0, false);
  const DirectionalLight front{both.frame.direction(deg_to_rad(30), 0), Rgb(2.0)};
  const DirectionalLight back{both.frame.direction(deg_to_rad(160), 1), Rgb(1.5, 1.0, 0.5)};
  both.lights.directional = {front, back};
  RenderSettings s = small_film(40, 32, 9);
  s.threads = 2;
  s.light_groups = true;
  const RenderResult grouped = render(RenderScene(both), *both.camera, s);
  ASSERT_EQ(grouped.light_images.size(), 2u);
  s.light_groups = false;
  double lit[2] = {0, 0};
  for (size_t k = 0; k < 2; ++k) {
    SceneDescription one = both;
    one.lights.directional = {k == 0 ? front : back};
    const RenderResult alone = render(RenderScene(one), *one.camera, s);
    const Image& im = grouped.light_images[k];
    ASSERT_EQ(im.rgb.size(), alone.image.rgb.size());
    EXPECT_EQ(0, std::memcmp(im.rgb.data(), alone.image.rgb.data(), im.rgb.size() * 4)) << k;
    for (float v : im.rgb) lit[k] += v;
  }
  EXPECT_GT(lit[0], 0);
  EXPECT_GT(lit[1], 0);  // light from behind passes through the cloth
  for (size_t i = 0; i < grouped.image.rgb.size(); ++i)
    EXPECT_NEAR(grouped.image.rgb[i],
                grouped.light_images[0].rgb[i] + grouped.light_images[1].rgb[i],
                1e-5 * (1 + grouped.image.rgb[i]));
  // Not with a time limit (the passes' sums would need a copy per light), nor over 4 lights.
  s.light_groups = true;
  s.time_limit_s = 10;
  EXPECT_THROW(render(RenderScene(both), *both.camera, s), Error);
  s.time_limit_s = 0;
  both.lights.directional.assign(5, front);
  EXPECT_THROW(render(RenderScene(both), *both.camera, s), Error);
}
