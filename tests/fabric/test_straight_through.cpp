// The light passing straight through the cloth, computed (fabric/straight_through.h): on sheets
// whose gap fraction is known for every direction, its plan, and its streams.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "flat_sheet.h"
#include "weft/core/direction_grid.h"
#include "weft/fabric/straight_through.h"
#include "weft/fabric/weave_tally.h"

using namespace weft;
using namespace weft::raytrace;

namespace {

using weft::testing::flat_sheet;

// The flat sheet cut to the half x < 0 of its repeat: a line through the slab crosses the sheet's
// plane once, at a point whose x is uniform over the period when its entry point is, so half of
// the lines pass, whatever their direction.
WovenSample half_sheet() {
  WovenSample s = flat_sheet();
  std::vector<float>& p = s.meshes[0].positions;
  for (size_t v = 0; v < p.size(); v += 3)
    if (p[v] > 0) p[v] = 0;
  return s;
}

// The half sheet ready to trace: its scene, the repeat's slab, and the R = 4 grid of kBins.
struct HalfSheetTrace {
  WovenSample sample = half_sheet();
  RenderScene scene{tiled_geometry(sample)};
  RepeatSlab slab = repeat_slab_of(sample);
  DirectionGrid grid{4};
};

// The incident bins whose straight-through cell the tests look at: normal, oblique, near the
// horizon, from above and from below (R = 4).
constexpr int kBins[] = {0, 5, 10, 15, 16, 21, 31};

}  // namespace

TEST(StraightThrough, HalfASheetPassesHalfTheLightOfEveryIncidentBin) {
  // The power per launched particle is E[|cos theta_i| 1{passes}] = 1/2 E[|cos theta_i|] over the
  // bin = 1/2 D_i / Omega (D_i the bin's cosine-weighted area, Omega its solid angle), in the
  // one cell of the direction continued: within 4 of the stated standard errors, which are small:
  // what remains is the spread of |cos theta_i| over the directions drawn, at most 2 % of the
  // power in the grazing bins.
  const HalfSheetTrace t;
  const auto& [sample, scene, slab, grid] = t;
  const auto d = grid.cosine_weighted_areas();
  const StraightThroughPlan plan = straight_through_plan(4000);
  for (const int bin : kBins) {
    const auto cells = straight_through_of_bin(scene, slab, grid, bin, plan, 1, 100000);
    ASSERT_EQ(cells.size(), 1u) << "bin " << bin;
    const int across = grid.bin_of(-grid.bin_center(bin));
    EXPECT_EQ(cells[0].cell, static_cast<uint64_t>(bin) * grid.bins() + across) << "bin " << bin;
    const double expected = 0.5 * d[bin] / grid.bin_solid_angle();
    const double sigma = std::sqrt(cells[0].variance);
    EXPECT_NEAR(cells[0].power, expected, 4 * sigma) << "bin " << bin;
    EXPECT_GT(sigma, 0) << "bin " << bin;
    EXPECT_LT(sigma, 0.02 * expected) << "bin " << bin;
  }
}

TEST(StraightThrough, AWholeSheetPassesNothing) {
  const WovenSample sample = flat_sheet();
  const RenderScene scene(tiled_geometry(sample));
  for (const int bin : kBins)
    EXPECT_TRUE(straight_through_of_bin(scene, repeat_slab_of(sample), DirectionGrid{4}, bin,
                                        straight_through_plan(1000), 1, 100000)
                    .empty())
        << "bin " << bin;
}

TEST(StraightThrough, PlanHasAtLeastOneRayPerParticleOnFibonacciLattices) {
  for (const uint64_t n : {uint64_t{1}, uint64_t{300}, uint64_t{20000}, uint64_t{1} << 30}) {
    const StraightThroughPlan plan = straight_through_plan(n);
    EXPECT_GE(plan.rays(), n);
    EXPECT_GE(plan.lattice_points, 5);
    // A Fibonacci number: 5 x^2 + 4 or 5 x^2 - 4 is a square (Gessel's test, 1972).
    const uint64_t x = static_cast<uint64_t>(plan.lattice_points);
    auto square = [](uint64_t v) {
      const auto r = static_cast<uint64_t>(std::llround(std::sqrt(double(v))));
      return r * r == v;
    };
    EXPECT_TRUE(square(5 * x * x + 4) || square(5 * x * x - 4)) << x;
  }
  // The smallest lattice that reaches the count: one size down would not.
  const StraightThroughPlan plan = straight_through_plan(20000);
  EXPECT_EQ(plan.lattice_points, 89);  // 55 x 256 = 14080 < 20000 <= 89 x 256
}

TEST(StraightThrough, StreamsAreTheSeedsAndBinsOwn) {
  const HalfSheetTrace t;
  const auto& [sample, scene, slab, grid] = t;
  const StraightThroughPlan plan = straight_through_plan(500);
  const auto a = straight_through_of_bin(scene, slab, grid, 5, plan, 1, 100000);
  const auto b = straight_through_of_bin(scene, slab, grid, 5, plan, 1, 100000);
  const auto c = straight_through_of_bin(scene, slab, grid, 5, plan, 2, 100000);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(a[0].power, b[0].power);
  EXPECT_EQ(a[0].variance, b[0].variance);
  EXPECT_NE(a[0].power, c[0].power);
}

TEST(StraightThrough, ItsRaysAreBookedWhereTheyCrossTheMidPlane) {
  // The half sheet lies in the slab's mid-plane (y = 0 of [-0.05, 0.05] mm) and covers its x < 0:
  // every ray that passes crosses it at x > 0, in the weave's position cells iu = 2, 3 of 4 along
  // x (weave_tally.h: u counted from the repeat's least x). Over the positions, the weave's cells
  // hold the table cell's power; the table cell keeps its bits (the weave draws nothing more).
  const HalfSheetTrace t;
  const auto& [sample, scene, slab, grid] = t;
  const StraightThroughPlan plan = straight_through_plan(1000);
  FabricRaytraceOptions o;
  o.resolution = 4;
  o.weave_positions_u = 4;
  o.weave_positions_v = 2;
  o.weave_resolution = 2;
  const WeaveLayout w = weave_layout(o, 3, slab.x0, slab.z0, slab.px, slab.pz, slab.y0, slab.y1);
  for (const int bin : kBins) {
    std::vector<StraightThroughCell> woven;
    const auto cells = straight_through_of_bin(scene, slab, grid, bin, plan, 1, 100000, &w, &woven);
    const auto alone = straight_through_of_bin(scene, slab, grid, bin, plan, 1, 100000);
    ASSERT_EQ(cells.size(), 1u) << "bin " << bin;
    ASSERT_EQ(alone.size(), 1u) << "bin " << bin;
    EXPECT_EQ(cells[0].power, alone[0].power) << "bin " << bin;
    EXPECT_EQ(cells[0].variance, alone[0].variance) << "bin " << bin;
    const uint64_t exit_bin = cells[0].cell - static_cast<uint64_t>(bin) * grid.bins();
    double power = 0;
    for (const StraightThroughCell& c : woven) {
      const uint64_t position = c.cell / w.coarse_bins;
      EXPECT_EQ(c.cell % w.coarse_bins, static_cast<uint64_t>(w.coarse_of_fine[exit_bin]));
      EXPECT_LT(position, 8u);
      EXPECT_GE(position % 4, 2u) << "bin " << bin << " position " << position;
      EXPECT_GE(c.variance, 0.0);
      power += c.power;
    }
    // Both open columns of both rows are met (the entry points cover the repeat).
    EXPECT_EQ(woven.size(), 4u) << "bin " << bin;
    EXPECT_NEAR(power, cells[0].power, 1e-12 * cells[0].power) << "bin " << bin;
  }
}
