// Nonwoven mats (nonwoven.h): the areal density, thickness and fiber orientations counted from
// the generated fibers against the request, periodicity (fibers continue across the tile's
// sides), determinism, no interpenetration, errors naming the field, and the bundled felt.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "lambert_scene.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

// A small mat (fast): 0.6 mm tile, 0.2 mm fibers of 9.5 um radius (the acrylic preset's),
// 100 g/m^2 of density 1.17 g/cm^3 in 1.2 mm: about 540 fibers, solidity 0.071.
WeaveOptions small_mat() {
  WeaveOptions o;
  o.pattern = kNonwovenPattern;
  o.tile_mm = 0.6;
  o.fiber_length_mm = 0.2;
  o.areal_density_gsm = 100;
  o.thickness_mm = 1.2;
  o.inclination_sd_deg = 15;
  o.fiber_radius_um = 9.5;
  o.fiber_density_g_cm3 = 1.17;
  o.seed = 7;
  return o;
}

// Each fiber's direction (unit, y >= 0 ... either sign), from its first piece.
std::map<uint32_t, Vec3> fiber_directions(const FiberCurves& f) {
  std::map<uint32_t, Vec3> dir;
  for (size_t c = 0; c < f.curve_count(); ++c) {
    if (dir.count(f.curve_yarn[c])) continue;
    dir[f.curve_yarn[c]] = normalize(f.point(f.curve_first[c] + 1) - f.point(f.curve_first[c]));
  }
  return dir;
}

using weft::testing::woven_sample_error;

}  // namespace

TEST(Nonwoven, ArealDensityAndThicknessMatchTheRequest) {
  const WeaveOptions o = small_mat();
  const WovenSample s = make_woven_sample(o);
  ASSERT_TRUE(s.summary.nonwoven);
  const double r = 9.5e-6, tile = 0.6e-3, rho = 1170;  // SI
  double length = 0;
  for (size_t c = 0; c < s.fibers.curve_count(); ++c)
    for (uint32_t k = 0; k + 1 < s.fibers.curve_points[c]; ++k)
      length += weft::length(s.fibers.point(s.fibers.curve_first[c] + k + 1) -
                             s.fibers.point(s.fibers.curve_first[c] + k));
  const double gsm = length * kPi * r * r * rho * 1e3 / (tile * tile);
  // The count is the requested fiber length over L, rounded: off by at most half a fiber
  // (0.1 mm of fiber: 0.1e-3 pi r^2 rho / tile^2 = 0.092 g/m^2), plus float storage.
  const double half_fiber = 0.1e-3 * kPi * r * r * rho * 1e3 / (tile * tile);
  EXPECT_NEAR(gsm, 100, half_fiber + 1e-4);
  EXPECT_NEAR(s.summary.nonwoven->areal_density_gsm, gsm, 1e-6 * gsm);
  // Every fiber surface inside the slab and the tile.
  for (size_t i = 0; i < s.fibers.point_count(); ++i) {
    const Vec3 p = s.fibers.point(i);
    EXPECT_LE(std::abs(p.y) + r, 0.6e-3 * (1 + 1e-6));
    EXPECT_LE(std::abs(p.x), 0.5 * tile * (1 + 1e-6));
    EXPECT_LE(std::abs(p.z), 0.5 * tile * (1 + 1e-6));
  }
  // Solidity: 100 g/m^2 / (1.17 g/cm^3 x 1.2 mm) = 0.0712.
  EXPECT_NEAR(s.summary.nonwoven->solidity, 100 / (1.17e6 * 1.2e-3), 1e-3);
}

TEST(Nonwoven, OrientationsFollowTheRequest) {
  const WovenSample s = make_woven_sample(small_mat());
  const auto dirs = fiber_directions(s.fibers);
  const double n = static_cast<double>(dirs.size());
  ASSERT_GT(n, 400);
  double c2 = 0, s2 = 0, theta2 = 0;
  for (const auto& [fiber, d] : dirs) {
    const double phi = std::atan2(d.z, d.x);
    c2 += std::cos(2 * phi), s2 += std::sin(2 * phi);
    const double theta = std::asin(std::clamp(d.y, -1.0, 1.0));
    theta2 += theta * theta;
  }
  // In-plane isotropy: cos 2 phi and sin 2 phi have mean 0 and variance 1/2 each; 4 standard
  // errors of the mean, sqrt(1 / (2 n)).
  const double se = std::sqrt(0.5 / n);
  EXPECT_LT(std::abs(c2 / n), 4 * se);
  EXPECT_LT(std::abs(s2 / n), 4 * se);
  // Inclination: zero-mean normal of sd 15 degrees; the sample sd's standard error is
  // sigma / sqrt(2 n). 4 of them.
  const double sd = rad_to_deg(std::sqrt(theta2 / n));
  EXPECT_NEAR(sd, 15, 4 * 15 / std::sqrt(2 * n));
  // No spread: every fiber in the plane.
  WeaveOptions flat = small_mat();
  flat.inclination_sd_deg = 0;
  for (const auto& [fiber, d] : fiber_directions(make_woven_sample(flat).fibers))
    EXPECT_NEAR(d.y, 0, 1e-6);
}

TEST(Nonwoven, FibersContinueAcrossTheTileSides) {
  const WovenSample s = make_woven_sample(small_mat());
  const FiberCurves& f = s.fibers;
  const double half = 0.3e-3, eps = 1e-9;
  int crossings = 0;
  for (size_t c = 0; c < f.curve_count(); ++c) {
    const Vec3 end = f.point(f.curve_first[c] + f.curve_points[c] - 1);
    for (const int axis : {0, 2}) {
      if (std::abs(std::abs(end[axis]) - half) > eps) continue;
      // The piece of the same fiber that starts on the opposite side at the same point.
      Vec3 want = end;
      want[axis] = -end[axis];
      bool found = false;
      for (size_t c2 = 0; c2 < f.curve_count() && !found; ++c2)
        found = f.curve_yarn[c2] == f.curve_yarn[c] &&
                weft::length(f.point(f.curve_first[c2]) - want) < 1e-9;
      EXPECT_TRUE(found) << "curve " << c;
      ++crossings;
    }
  }
  EXPECT_GT(crossings, 50);  // 0.2 mm fibers in a 0.6 mm tile: about a third cross a side
  EXPECT_GE(s.summary.min_fiber_distance_um, 2 * 9.5 * (1 - 1e-2));  // no interpenetration
}

TEST(Nonwoven, SameSeedSameFibers) {
  const WovenSample a = make_woven_sample(small_mat()), b = make_woven_sample(small_mat());
  EXPECT_EQ(a.fibers.points, b.fibers.points);
  WeaveOptions other = small_mat();
  other.seed = 8;
  EXPECT_NE(make_woven_sample(other).fibers.points, a.fibers.points);
}

TEST(Nonwoven, BadParametersAreErrorsNamingTheField) {
  using Change = std::function<void(WeaveOptions&)>;
  const std::pair<std::string, Change> cases[] = {
      {"areal-density-gsm", [](WeaveOptions& o) { o.areal_density_gsm = -1; }},
      {"thickness-mm", [](WeaveOptions& o) { o.thickness_mm = 0; }},
      {"thickness-mm", [](WeaveOptions& o) { o.thickness_mm = 0.1; }},  // solidity 0.85
      {"solidity", [](WeaveOptions& o) { o.thickness_mm.reset(), o.solidity = 0.9; }},
      {"solidity", [](WeaveOptions& o) { o.solidity = 0.1; }},  // both given
      {"inclination-sd-deg", [](WeaveOptions& o) { o.inclination_sd_deg = 60; }},
      {"fiber-length-mm", [](WeaveOptions& o) { o.fiber_length_mm = 0.4; }},  // > tile / 2
      {"tile-mm", [](WeaveOptions& o) { o.tile_mm = NAN; }},
      {"fiber-density-g-cm3", [](WeaveOptions& o) { o.fiber_density_g_cm3 = 0; }},
      {"fiber-radius-um", [](WeaveOptions& o) { o.fiber_radius_um = 0; }},
      {"detail", [](WeaveOptions& o) { o.detail = "yarn"; }},
      {"packing", [](WeaveOptions& o) { o.packing = 0.5; }},  // woven only
      // Too many fibers: refused from the estimate (20 mm tile: 1.3 M fibers).
      {"areal-density-gsm",
       [](WeaveOptions& o) { o.tile_mm = 20, o.fiber_length_mm = 0.2, o.areal_density_gsm = 500; }},
  };
  for (const auto& [field, change] : cases) {
    WeaveOptions o = small_mat();
    change(o);
    const std::string e = woven_sample_error(o);
    EXPECT_NE(e.find("field '" + field + "'"), std::string::npos) << field << ": " << e;
  }
  // A mat option with a woven pattern.
  WeaveOptions woven;
  woven.areal_density_gsm = 100;
  EXPECT_NE(woven_sample_error(woven).find("field 'areal-density-gsm'"), std::string::npos);
  // A mat too dense to place: no free height in 2000 tries, named by the thickness.
  WeaveOptions dense = small_mat();
  dense.thickness_mm.reset();
  dense.solidity = 0.5;
  dense.fiber_length_mm = 0.3;
  const std::string e = woven_sample_error(dense);
  EXPECT_NE(e.find("field 'solidity'"), std::string::npos) << e;
  EXPECT_NE(e.find("does not fit"), std::string::npos) << e;
}

TEST(Nonwoven, BundledFeltIsTheDefault) {
  const auto file = std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/examples/acrylic-felt.json";
  WeaveOptions plain;
  plain.pattern = kNonwovenPattern;
  const WovenSample a = make_woven_sample(read_weave_options(file)), b = make_woven_sample(plain);
  EXPECT_EQ(a.fibers.points, b.fibers.points);
  ASSERT_TRUE(a.summary.nonwoven);
  EXPECT_NEAR(a.summary.nonwoven->areal_density_gsm, 170, 0.5);
  EXPECT_EQ(a.summary.period_x_mm, 1.2);
}

// nonwoven_sample_size (what a plan counts, the mat not made): the fibers exactly and the curves
// (fibers cut at the tile's sides) as expected: 766 against 742 made for the small mat (540
// fibers: the cuts' own spread is about 2 %), 2 602 against 2 595 for the bundled felt. And the
// placement tries its making time is estimated from (NonwovenSize): within 2x of those the
// placement took (the small mat about 1 a fiber, the felt about 3.1; the estimate once counted the
// felt's points alone and put the largest mat at under a second against 37 s of CPU).
TEST(Nonwoven, SizeBeforeTheMatIsMadeIsClose) {
  const auto felt = std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/examples/acrylic-felt.json";
  for (const WeaveOptions& o : {small_mat(), read_weave_options(felt)}) {
    const NonwovenSize z = nonwoven_sample_size(o);
    const WovenSample s = make_woven_sample(o);
    ASSERT_TRUE(s.summary.nonwoven);
    EXPECT_EQ(z.fibers, s.summary.nonwoven->fibers);
    EXPECT_NEAR(z.curves / double(s.summary.curves), 1.0, 0.05)
        << s.summary.curves << " made, " << z.curves << " expected";
    const WovenSampleSize w = woven_sample_size(o);
    EXPECT_EQ(w.curves, z.curves);
    EXPECT_EQ(w.curve_points, 2 * z.curves);
    EXPECT_EQ(w.curve_segments, z.curves);
    const double tries = s.summary.nonwoven->attempts;
    EXPECT_GT(z.placement_tries, 0.5 * tries) << tries << " tries made";
    EXPECT_LT(z.placement_tries, 2.0 * tries) << tries << " tries made";
    EXPECT_GE(z.placement_tries, z.fibers);
    EXPECT_GT(w.placement_crossing_checks, 0);
    EXPECT_GT(w.placement_copy_checks, 0);
  }
}
