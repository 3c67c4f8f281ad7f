// The car seat (scenes/car_seat.h) in the bundled description (scenes/examples/car-seat):
//  * it loads with every panel bound and renders finite;
//  * the three upholstery variants (measured NBRDF, a summed fabric table, the classic fiber
//    baseline) differ on the fabric and nowhere else: with direct light only (max_depth 1) a
//    pixel whose samples all land on the ground or the base does not depend on the seat's BSDF,
//    so it is bit-identical across variants (the random streams depend on seed, pixel and sample
//    only, core/rng.h);
//  * a summed fabric table that transmits renders brighter on a backing (backing_reflectance:
//    the light it transmits comes back instead of being lost in the seat's body), and finite;
//  * a fabric table baked from a Lambert BSDF renders the Lambert image on the curved panels:
//    the shading frame (panel normal, warp tangent, binormal) and the table's lookup and sampling
//    add nothing (as tests/integrators/test_table_material.cpp shows on a plane).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/car_seat.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {
const fs::path kSeatDir = fs::path(WEFT_SOURCE_DIR) / "scenes/examples/car-seat";
const char* const kFabricKeys[] = {"centre", "bolster", "piping", "headrest"};

// The bundled description with a coarse seat written next to it in a temporary folder.
nlohmann::json seat_description(const fs::path& dir) {
  CarSeatOptions o;
  o.cell_mm = 20;
  write_car_seat_gltf(dir / "seat.glb", make_car_seat(o), o);
  std::ifstream in(kSeatDir / "car-seat.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["gltf"] = (dir / "seat.glb").string();
  return j;
}

void bind_fabric(nlohmann::json& j, const nlohmann::json& binding) {
  for (const char* key : kFabricKeys) j["materials"][key] = binding;
}

// The fiber table 'fiber' summed into a fabric table (R = 4) by the paper's formula, written to
// 'file'.
fs::path write_summed(TabulatedBsdfTable fiber, const fs::path& file) {
  fiber.kind = "fiber";
  FabricSummationOptions o;
  o.resolution = 4;
  o.samples_per_cell = 2;
  sum_fabric_table(fiber, o).write_exr(file);
  return file;
}

// A red-tinted Lambert fiber table summed into a fabric table by the paper's formula.
fs::path summed_fabric_table(const fs::path& dir) {
  auto fiber = TabulatedBsdfTable::from_function(
      4, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const bool lit = wo.z > 0 && wi.z > 0;
        v[0] = lit ? 0.7 * kInvPi : 0.0;
        v[1] = v[2] = lit ? 0.1 * kInvPi : 0.0;
      },
      2, 1);
  return write_summed(std::move(fiber), dir / "fabric.exr");
}

// A red fiber table that also transmits (like the baked red-cotton one, which transmits more
// than it reflects), summed into a fabric table by the paper's formula.
fs::path summed_transmitting_fabric_table(const fs::path& dir) {
  auto fiber = TabulatedBsdfTable::from_function(
      4, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        // Like a baked fiber table, light leaves only through the point (w_o above it).
        const bool lit = wo.z > 0 && wi.z > 0, through = wo.z > 0 && wi.z < 0;
        v[0] = (lit ? 0.25 : through ? 0.6 : 0.0) * kInvPi;
        v[1] = v[2] = (lit ? 0.04 : through ? 0.1 : 0.0) * kInvPi;
      },
      2, 1);
  return write_summed(std::move(fiber), dir / "fabric-transmitting.exr");
}

// Per pixel: the mesh every sample's camera ray met first, or -2 when they differ (-1: none).
struct Classified {
  RenderResult result;
  std::vector<int64_t> first;
};
Classified render_classified(const SceneDescription& d, const RenderSettings& s) {
  Classified c;
  c.first.assign(size_t(s.width) * s.height, -3);
  RenderObservers obs;
  obs.on_sample = [&](uint64_t pixel, int64_t first, const Rgb&) {
    int64_t& f = c.first[pixel];
    f = f == -3 ? first : (f == first ? f : -2);
  };
  RenderSettings one = s;
  one.threads = 1;  // the observer writes without locks
  c.result = render(RenderScene(d), *d.camera, one, no_progress(), obs);
  return c;
}

}  // namespace

TEST(CarSeatScene, BundledDescriptionLoadsAndRendersFinite) {
  const fs::path dir = weft::testing::fresh_test_dir();
  const SceneDescription d = parse_scene_description(seat_description(dir), kSeatDir, "seat.json");
  ASSERT_TRUE(d.camera);
  EXPECT_EQ(d.lights.directional.size(), 1u);
  EXPECT_EQ(d.lights.environment_maps.size(), 1u);  // the sky
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
  RenderSettings s;
  s.width = 40, s.height = 30, s.spp = 1, s.max_depth = 2;
  const RenderResult r = render(RenderScene(d), *d.camera, s);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  double sum = 0;
  for (float v : r.image.rgb) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0);
    sum += v;
  }
  EXPECT_GT(sum, 0);
}

// The ground reaches the horizon: the sky is 0 below it (environment_map.h), so a ground that
// ended short of it (the 200 m quad alone: 0.57 degrees below the horizon from the camera's 1 m
// height, 6 pixels of the bundled 480 x 360 view) left a black band between ground and sky. The
// rows around the horizon left of the seat (the bundled view's pixels x < 240, y 26 to 47 see only
// ground and sky) are no darker than half their mean anywhere.
TEST(CarSeatScene, GroundMeetsTheSkyAtTheHorizon) {
  const fs::path dir = weft::testing::fresh_test_dir();
  const SceneDescription d = parse_scene_description(seat_description(dir), kSeatDir, "seat.json");
  RenderSettings s;
  s.width = 480, s.height = 360, s.spp = 4, s.max_depth = 1;
  s.crop = PixelWindow{0, 240, 26, 48};
  const RenderResult r = render(RenderScene(d), *d.camera, s);
  const size_t n = r.image.rgb.size() / 3;
  ASSERT_EQ(n, 240u * 22u);
  double mean = 0;
  for (float v : r.image.rgb) mean += v;
  mean /= 3.0 * n;
  ASSERT_GT(mean, 0);
  for (size_t p = 0; p < n; ++p)
    ASSERT_GT(r.image.rgb[3 * p], 0.5 * mean)
        << "pixel x " << p % 240 << ", y " << 26 + p / 240 << " (crop mean " << mean << ")";
}

TEST(CarSeatScene, ThreeVariantsDifferOnTheFabricAndNowhereElse) {
  const fs::path dir = weft::testing::fresh_test_dir();
  nlohmann::json base = seat_description(dir);
  nlohmann::json measured = base, table = base, classic = base;  // bundled: measured_nbrdf
  bind_fabric(
      table, {{"type", "fabric_table"}, {"params", {{"file", summed_fabric_table(dir).string()}}}});
  bind_fabric(classic, {{"type", "classic_fiber"},
                        {"params", {{"reflectance", {0.45, 0.06, 0.05}}, {"alpha", 0.35}}}});
  RenderSettings s;
  s.width = 64, s.height = 48, s.spp = 2, s.max_depth = 1, s.seed = 5;
  std::vector<Classified> v;
  std::vector<SceneDescription> descs;
  for (const auto* j : {&measured, &table, &classic})
    descs.push_back(parse_scene_description(*j, kSeatDir, "seat.json"));
  for (const auto& d : descs) v.push_back(render_classified(d, s));
  // Which meshes are fabric, which are not (ground quad, base, posts).
  const SceneDescription& d = descs[0];
  auto is_fabric = [&](int64_t mesh) {
    if (mesh < 0 || size_t(mesh) >= d.meshes.size()) return false;
    for (const char* key : kFabricKeys)
      if (d.meshes[mesh]->material == key) return true;
    return false;
  };
  size_t fabric_pixels = 0, other_pixels = 0;
  std::vector<double> diff(3, 0.0), level(3, 0.0);
  for (size_t p = 0; p < v[0].first.size(); ++p) {
    const int64_t f = v[0].first[p];
    ASSERT_EQ(f, v[1].first[p]);  // the camera rays are the same
    if (f == -2) continue;        // mixed pixel
    for (int c = 0; c < 3; ++c) {
      const double a = v[0].result.image.rgb[3 * p + c], b = v[1].result.image.rgb[3 * p + c],
                   e = v[2].result.image.rgb[3 * p + c];
      if (is_fabric(f)) {
        diff[0] += std::abs(a - b), diff[1] += std::abs(a - e), diff[2] += std::abs(b - e);
        level[0] += a, level[1] += b, level[2] += e;
      } else {
        ASSERT_EQ(a, b) << "pixel " << p << " (mesh " << f << ")";
        ASSERT_EQ(a, e) << "pixel " << p << " (mesh " << f << ")";
      }
    }
    (is_fabric(f) ? fabric_pixels : other_pixels)++;
  }
  ASSERT_GT(fabric_pixels, 300u);
  ASSERT_GT(other_pixels, 300u);
  const double mean_level = (level[0] + level[1] + level[2]) / 3;
  ASSERT_GT(mean_level, 0);
  // Three different BSDFs on the panels: every pair differs by more than 5% of the fabric's
  // mean radiance, pixel by pixel on average (the models differ by tens of percent).
  for (int k = 0; k < 3; ++k) EXPECT_GT(diff[k] / mean_level, 0.05) << "pair " << k;
}

TEST(CarSeatScene, ComputedFabricOnAFoamBackingIsBrighterAndFinite) {
  const fs::path dir = weft::testing::fresh_test_dir();
  const std::string table = summed_transmitting_fabric_table(dir).string();
  nlohmann::json bare = seat_description(dir), backed = bare;
  bind_fabric(bare, {{"type", "fabric_table"}, {"params", {{"file", table}}}});
  bind_fabric(backed, {{"type", "fabric_table"},
                       {"params", {{"file", table}, {"backing_reflectance", 0.6}}}});
  RenderSettings s;
  s.width = 48, s.height = 36, s.spp = 2, s.max_depth = 3, s.seed = 3;
  const SceneDescription db = parse_scene_description(bare, kSeatDir, "seat.json");
  const SceneDescription dk = parse_scene_description(backed, kSeatDir, "seat.json");
  const Classified a = render_classified(db, s), b = render_classified(dk, s);
  EXPECT_EQ(a.result.nonfinite_samples, 0u);
  EXPECT_EQ(b.result.nonfinite_samples, 0u);
  auto is_fabric = [&](int64_t mesh) {
    if (mesh < 0 || size_t(mesh) >= db.meshes.size()) return false;
    for (const char* key : kFabricKeys)
      if (db.meshes[mesh]->material == key) return true;
    return false;
  };
  Rgb sum_bare, sum_backed;
  size_t pixels = 0;
  for (size_t p = 0; p < a.first.size(); ++p) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(b.result.image.rgb[3 * p + c]));
      ASSERT_GE(b.result.image.rgb[3 * p + c], 0);
    }
    if (!is_fabric(a.first[p])) continue;
    ++pixels;
    sum_bare += Rgb(a.result.image.rgb[3 * p], a.result.image.rgb[3 * p + 1],
                    a.result.image.rgb[3 * p + 2]);
    sum_backed += Rgb(b.result.image.rgb[3 * p], b.result.image.rgb[3 * p + 1],
                      b.result.image.rgb[3 * p + 2]);
  }
  ASSERT_GT(pixels, 200u);
  // The backing returns ρ_b τ(wo) T_d / (1 − ρ_b r_under) of the light: 0.6 · 0.6 · 0.6 = 0.22
  // of red (the paper's sum reflects nothing below the cloth, r_under = 0) on top of a
  // reflectance of 0.25: far more than the noise of 2 spp.
  EXPECT_GT(sum_backed.r, 1.3 * sum_bare.r);
  EXPECT_GT(sum_backed.g, sum_bare.g);
}

TEST(CarSeatScene, LambertFabricTableRendersTheLambertImage) {
  const fs::path dir = weft::testing::fresh_test_dir();
  const Rgb rho{0.6, 0.25, 0.15};
  auto lam_table = TabulatedBsdfTable::from_function(
      8, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const bool same_side = wo.z * wi.z > 0;  // two-sided, as lambert is
        v[0] = same_side ? rho.r * kInvPi : 0.0;
        v[1] = same_side ? rho.g * kInvPi : 0.0;
        v[2] = same_side ? rho.b * kInvPi : 0.0;
      },
      2, 1);
  lam_table.kind = "fabric";
  lam_table.write_exr(dir / "lambert-fabric.exr");
  nlohmann::json lam = seat_description(dir), tab = lam;
  bind_fabric(lam, {{"type", "lambert"}, {"params", {{"reflectance", {rho.r, rho.g, rho.b}}}}});
  bind_fabric(tab, {{"type", "fabric_table"},
                    {"params", {{"file", (dir / "lambert-fabric.exr").string()}}}});
  const SceneDescription a = parse_scene_description(lam, kSeatDir, "seat.json");
  const SceneDescription b = parse_scene_description(tab, kSeatDir, "seat.json");

  // Direct sunlight only: no sampling of the BSDF matters, so the images agree to the table's
  // float storage (1e-6 relative) wherever the frames agree.
  {
    SceneDescription sa = a, sb = b;
    sa.lights.environment = sb.lights.environment = Rgb(0.0);
    sa.lights.environment_maps.clear();
    sb.lights.environment_maps.clear();
    RenderSettings s;
    s.width = 48, s.height = 36, s.spp = 2, s.max_depth = 1;
    const RenderResult ra = render(RenderScene(sa), *sa.camera, s);
    const RenderResult rb = render(RenderScene(sb), *sb.camera, s);
    double max_rel = 0, sum = 0;
    for (size_t i = 0; i < ra.image.rgb.size(); ++i) {
      sum += ra.image.rgb[i];
      if (ra.image.rgb[i] > 1e-6)
        max_rel = std::max(max_rel,
                           std::abs(double(ra.image.rgb[i]) - rb.image.rgb[i]) / ra.image.rgb[i]);
    }
    ASSERT_GT(sum, 0);
    EXPECT_LT(max_rel, 1e-4);
  }
  // Sun, sky and inter-reflection: the table samples its own directions, so the images differ
  // by noise only: the mean per-pixel difference lies within 4 standard errors of zero.
  {
    RenderSettings s;
    s.width = 32, s.height = 24, s.spp = 8, s.max_depth = 3;
    const RenderResult ra = render(RenderScene(a), *a.camera, s);
    const RenderResult rb = render(RenderScene(b), *b.camera, s);
    const size_t n = ra.image.rgb.size();
    double m = 0, m2 = 0, level = 0;
    for (size_t i = 0; i < n; ++i) {
      const double dlt = double(ra.image.rgb[i]) - rb.image.rgb[i];
      m += dlt, m2 += dlt * dlt, level += ra.image.rgb[i];
    }
    m /= n, m2 /= n, level /= n;
    const double se = std::sqrt(std::max(0.0, m2 - m * m) / n);
    ASSERT_GT(level, 0);
    EXPECT_LT(std::abs(m), 4 * se + 1e-6 * level) << "mean difference " << m << ", se " << se;
    EXPECT_LT(std::abs(m) / level, 0.02);
  }
}
