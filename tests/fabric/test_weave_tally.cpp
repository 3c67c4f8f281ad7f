// The ray trace's weave tally (fabric/weave_tally.h): its position mean is the fabric table's
// coarse average, a visible structure shows, it is deterministic at any thread count and in pieces,
// and bad options are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "raytrace_test_util.h"
#include "test_util.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/fabric/weave_tally.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

// A lossy fiber that sends a fraction of the light to its outer hemisphere (as
// test_fabric_raytrace.cpp's uniform_fiber).
TabulatedBsdfTable lossy_fiber(int resolution) {
  auto t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [](const Vec3& wo, const Vec3&, std::span<double> v) {
        v[0] = wo.z > 0 ? 0.4 * kInvPi : 0.0;
        v[1] = 0.7 * v[0];
        v[2] = 0.3 * v[0];
      },
      2, 1);
  t.kind = "fiber";
  return t;
}

using weft::testing::default_sample;

FabricRaytraceOptions weave_options(int resolution, uint64_t particles, int pu, int pv,
                                    int weave_resolution) {
  FabricRaytraceOptions o = weft::testing::options(resolution, particles);
  o.weave_positions_u = pu;
  o.weave_positions_v = pv;
  o.weave_resolution = weave_resolution;
  return o;
}

// The mean over the positions of m is 1 wherever the booked mean is above 0 (and m is 1 where it
// is 0), and that mean is the fabric table's coarse average of the same run: every exit the table
// books is booked once in the weave (weave_tally.h).
void expect_position_mean_is_the_table(const FabricRaytraceResult& r) {
  const WeaveTable& w = r.weave;
  const std::vector<double> coarse = coarse_table_average(r.table, w.resolution);
  ASSERT_EQ(r.weave_mean.size(), coarse.size());
  size_t nonzero = 0;
  for (int i = 0; i < w.bins(); ++i)
    for (int o = 0; o < w.bins(); ++o)
      for (int c = 0; c < w.channels; ++c) {
        const size_t k = (static_cast<size_t>(i) * w.bins() + o) * w.channels + c;
        // The table is stored as floats: its coarse average agrees to float rounding.
        EXPECT_NEAR(r.weave_mean[k], coarse[k], 1e-6 * coarse[k] + 1e-12) << i << " " << o;
        double m = 0;
        for (int p = 0; p < w.positions(); ++p) m += w.modulation[w.index(p, i, o, c)];
        m /= w.positions();
        EXPECT_NEAR(m, 1.0, 1e-5);
        if (coarse[k] > 0) {
          ++nonzero;
        } else {
          for (int p = 0; p < w.positions(); ++p)
            EXPECT_EQ(w.modulation[w.index(p, i, o, c)], 1.0f);
        }
      }
  EXPECT_GT(nonzero, coarse.size() / 4);
}

// Both ways of booking the light that meets no fiber (FabricRaytraceOptions::straight_through).
constexpr StraightThrough kStraightThrough[] = {StraightThrough::exact, StraightThrough::sampled};

}  // namespace

TEST(WeaveTally, PositionMeanIsTheTablesCoarseAverage) {
  const WovenSample sample = default_sample("yarn");
  const auto fiber = lossy_fiber(3);
  // Nested grids (R 4 over 2) and not (R 3 over 2), positions not square, hero and nee exits; the
  // straight-through light computed (its rays booked by position too) and sampled.
  for (const StraightThrough st : kStraightThrough)
    for (const auto& [r, rw] : {std::pair{4, 2}, std::pair{3, 2}}) {
      SCOPED_TRACE(name_of(kStraightThroughNames, st));
      FabricRaytraceOptions o = weave_options(r, 400, 4, 3, rw);
      o.straight_through = st;
      const auto hero = raytrace_fabric_table(sample, fiber, o);
      ASSERT_EQ(hero.weave.positions_u, 4);
      ASSERT_EQ(hero.weave.positions_v, 3);
      EXPECT_NO_THROW(hero.weave.validate(""));
      // It belongs to this table, and its file reads back as written.
      EXPECT_EQ(hero.weave.metadata.at("fabric_checksum"), hero.table.checksum());
      const auto file = weft::testing::fresh_test_dir() / "weave.exr";
      hero.weave.write_exr(file);
      const WeaveTable back = WeaveTable::read_exr(file);
      EXPECT_EQ(back.modulation, hero.weave.modulation);
      EXPECT_EQ(back.repeat_u_m, hero.weave.repeat_u_m);
      expect_position_mean_is_the_table(hero);
      EXPECT_GT(hero.weave_relative_noise, 0.0);
      // The weave tally draws no random number: the table keeps its bits with it off.
      FabricRaytraceOptions off = o;
      off.weave_positions_u = off.weave_positions_v = 0;
      const auto plain = raytrace_fabric_table(sample, fiber, off);
      EXPECT_EQ(plain.table.values, hero.table.values);
      EXPECT_EQ(plain.relative_noise, hero.relative_noise);
      EXPECT_TRUE(plain.weave.modulation.empty());
      o.next_event_rays = 1;
      o.launch_lattice = 13;
      expect_position_mean_is_the_table(raytrace_fabric_table(sample, fiber, o));
    }
}

TEST(WeaveTally, NoiseMatchesTheSpreadOfIndependentRuns) {
  // Two seeds' booked values B = m x the position mean differ by sqrt(2) x the stated relative
  // noise (weighted as it is: D_i D_o over the coarse cells), within 25 % (as the table's noise is
  // checked in test_fabric_raytrace.cpp); with the hero estimator and with nee's launch blocks.
  const WovenSample sample = default_sample("yarn");
  const auto fiber = lossy_fiber(3);
  for (const int next_event_rays : {0, 1}) {
    FabricRaytraceOptions o = weave_options(4, 4000, 4, 4, 2);
    o.next_event_rays = next_event_rays;
    o.launch_lattice = next_event_rays ? 13 : 1;
    const auto a = raytrace_fabric_table(sample, fiber, o);
    o.seed = 2;
    const auto b = raytrace_fabric_table(sample, fiber, o);
    const DirectionGrid fine{4}, coarse{2};
    const std::vector<int> of = coarse_bins_of(fine, coarse);
    std::vector<double> area(coarse.bins(), 0.0);
    for (int k = 0; k < fine.bins(); ++k) area[of[k]] += fine.cosine_weighted_areas()[k];
    double diff2 = 0, ref2 = 0;
    const WeaveTable& w = a.weave;
    for (int p = 0; p < w.positions(); ++p)
      for (int i = 0; i < w.bins(); ++i)
        for (int k = 0; k < w.bins(); ++k)
          for (int c = 0; c < 3; ++c) {
            const size_t m = (static_cast<size_t>(i) * w.bins() + k) * 3 + c;
            const double ba = a.weave_mean[m] * w.modulation[w.index(p, i, k, c)];
            const double bb = b.weave_mean[m] * b.weave.modulation[w.index(p, i, k, c)];
            diff2 += area[i] * area[k] * (ba - bb) * (ba - bb);
            ref2 += area[i] * area[k] * ba * ba;
          }
    const double stated = std::sqrt(a.weave_relative_noise * a.weave_relative_noise +
                                    b.weave_relative_noise * b.weave_relative_noise);
    EXPECT_NEAR(std::sqrt(diff2 / ref2) / stated, 1.0, 0.25)
        << std::sqrt(diff2 / ref2) << " vs " << stated << " (nee " << next_event_rays << ")";
  }
}

namespace {

// Whether vertical lines through position cell (iu, iv) of the weave's layout (weave_tally.h: u
// from the repeat's least x, v from its greatest z towards -z) meet a yarn: the fraction of a
// k x k grid of them that do, from the sample's own geometry (the repeat and its neighbours).
double covered_fraction(const RenderScene& scene, const raytrace::RepeatSlab& r, int positions,
                        int iu, int iv) {
  constexpr int k = 5;
  int hits = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const double fu = (iu + (i + 0.5) / k) / positions, fv = (iv + (j + 0.5) / k) / positions;
      const Vec3 p{r.x0 + r.px * fu, r.y1 + 1e-6, r.z0 + r.pz - r.pz * fv};
      SurfaceHit h;
      hits += scene.intersect({p, {0, -1, 0}, 1e300}, &h);
    }
  return static_cast<double>(hits) / (k * k);
}

}  // namespace

TEST(WeaveTally, GapsBetweenYarnsTransmitStraightThrough) {
  // A plain weave with yarns half as wide as their spacing: square gaps of 0.2 mm, 8 x 8 cells of
  // 0.1 mm over the 0.8 mm repeat, so some cells lie wholly in a gap and some wholly on yarns.
  WeaveOptions open;
  open.pattern = "plain";
  open.warp_spacing_mm = open.weft_spacing_mm = 0.4;
  open.warp_width_mm = open.weft_width_mm = 0.2;
  const WovenSample sample = default_sample("yarn", open);
  // Light from straight above: the incident bin holding the normal (odd R: its centre), and the
  // coarse cell of the light leaving straight down (the weave at the table's R, so that coarse
  // cell is as narrow as the table's).
  constexpr int kR = 5, kPositions = 8;
  FabricRaytraceOptions o = weave_options(kR, 6000, kPositions, kPositions, kR);
  const DirectionGrid grid{kR};
  o.first_bin = grid.bin_of({0, 0, 1});
  o.bin_count = 1;
  const int wi = grid.bin_of({0, 0, 1}), wo = grid.bin_of({0, 0, -1});
  const raytrace::RepeatSlab slab = raytrace::repeat_slab_of(sample);
  const RenderScene scene(raytrace::tiled_geometry(sample));
  // The light through the gaps computed (its rays booked where they cross the mid-plane) and
  // sampled (the particles that meet nothing booked there).
  for (const StraightThrough st : kStraightThrough) {
    SCOPED_TRACE(name_of(kStraightThroughNames, st));
    o.straight_through = st;
    const auto res = raytrace_fabric_table(sample, lossy_fiber(3), o);
    int gaps = 0, covered = 0;
    for (int iv = 0; iv < kPositions; ++iv)
      for (int iu = 0; iu < kPositions; ++iu) {
        const double f = covered_fraction(scene, slab, kPositions, iu, iv);
        const int pos = iv * kPositions + iu;
        for (int c = 0; c < 3; ++c) {
          const float m = res.weave.modulation[res.weave.index(pos, wi, wo, c)];
          if (f == 0) {
            EXPECT_GT(m, 1.0f) << "gap cell " << iu << " " << iv << " channel " << c;
          } else if (f == 1) {
            EXPECT_LT(m, 1.0f) << "yarn cell " << iu << " " << iv << " channel " << c;
          }
        }
        gaps += f == 0, covered += f == 1;
      }
    // The geometry as described: a quarter of the repeat open, 2 x 2 cells per gap at least.
    EXPECT_GE(gaps, 4 * 2);
    EXPECT_GE(covered, 16);
  }
}

TEST(WeaveTally, BitIdenticalAtAnyThreadCountAndInParts) {
  const WovenSample sample = default_sample("fiber");
  const auto fiber = lossy_fiber(3);
  FabricRaytraceOptions o = weave_options(2, 300, 3, 3, 1);
  o.threads = 1;
  const auto one = raytrace_fabric_table(sample, fiber, o);
  o.threads = 2;
  const auto two = raytrace_fabric_table(sample, fiber, o);
  EXPECT_EQ(one.weave.modulation, two.weave.modulation);
  EXPECT_EQ(one.weave_relative_noise, two.weave_relative_noise);
  // Pieces of the incident bins, encoded as part units and assembled (weft merge's path).
  const int bins = DirectionGrid{2}.bins();
  std::map<uint64_t, std::vector<double>> units;
  for (const auto& [first, count] : {std::pair{0, 3}, std::pair{3, bins - 3}}) {
    FabricRaytraceOptions p = o;
    p.first_bin = first;
    p.bin_count = count;
    const auto piece = raytrace_fabric_table(sample, fiber, p);
    for (int a = first; a < first + count; ++a)
      encode_fabric_bin(piece, static_cast<uint64_t>(a), units[static_cast<uint64_t>(a)]);
  }
  const WeaveShape shape{3, 3, 1, two.weave.repeat_u_m, two.weave.repeat_v_m};
  auto merged = assemble_fabric_bins(units, 0, bins, 2, 3, shape);
  EXPECT_EQ(merged.table.values, two.table.values);
  EXPECT_EQ(merged.weave.modulation, two.weave.modulation);
  EXPECT_EQ(merged.weave_mean, two.weave_mean);
  EXPECT_EQ(merged.weave_relative_noise, two.weave_relative_noise);
  // Without the shape, a weave-carrying unit is another size: refused, not misread.
  EXPECT_THROW(assemble_fabric_bins(units, 0, bins, 2, 3), Error);
}

TEST(WeaveTally, BadOptionsAreRefusedByName) {
  const WovenSample sample = default_sample("yarn");
  const auto fiber = lossy_fiber(3);
  auto refused_field = [&](const FabricRaytraceOptions& o) -> std::string {
    try {
      raytrace_fabric_table(sample, fiber, o);
    } catch (const Error& e) {
      return e.what();
    }
    return "accepted";
  };
  auto names = [](const std::string& message, const std::string& field) {
    return message.find("field '" + field + "'") != std::string::npos;
  };
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, 65, 8, 1)), "weave_positions_u");
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, -1, 8, 1)), "weave_positions_u");
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, 8, 0, 1)), "weave_positions_v");
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, 0, 8, 1)), "weave_positions_u");
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, 8, 8, 0)), "weave_resolution");
  EXPECT_PRED2(names, refused_field(weave_options(2, 10, 8, 8, 3)), "weave_resolution");
  // Off, the weave's resolution is not looked at (its default 4 above this table's R 2).
  EXPECT_EQ(refused_field(weave_options(2, 10, 0, 0, 4)), "accepted");
}

TEST(WeaveTally, PositionIsWhereTheLineCrossesTheMidPlane) {
  FabricRaytraceOptions o = weave_options(2, 1, 4, 2, 1);
  // Repeat [-0.5, 0.5] mm in x and z, slab [0, 0.2] mm: the mid-plane at y = 0.1 mm.
  const raytrace::WeaveLayout w =
      raytrace::weave_layout(o, 3, -0.5e-3, -0.5e-3, 1e-3, 1e-3, 0, 0.2e-3);
  // Straight down through (x, z) = (0.1, 0.3) mm: u = 0.6 -> iu 2; v = (0.5 - 0.3) / 1 -> iv 0.
  EXPECT_EQ(raytrace::weave_position(w, {0.1e-3, 0.2e-3, 0.3e-3}, {0, -1, 0}), 0 * 4 + 2);
  // Leaving upwards at 45 degrees along +x from (0.45, 0.2, -0.3) mm: its line crossed the
  // mid-plane 0.1 mm back, at x = 0.35 mm (u = 0.85 -> iu 3), z = -0.3 mm (v = 0.8 -> iv 1).
  const Vec3 d = normalize(Vec3{1, 1, 0});
  EXPECT_EQ(raytrace::weave_position(w, {0.45e-3, 0.2e-3, -0.3e-3}, d), 1 * 4 + 3);
  // Wrapped: 1.35 mm further along x is the same cell.
  EXPECT_EQ(raytrace::weave_position(w, {1.45e-3, 0.2e-3, -0.3e-3}, d), 1 * 4 + 3);
  EXPECT_EQ(raytrace::weave_position(w, {-0.55e-3, 0.2e-3, -0.3e-3}, d), 1 * 4 + 3);
}
