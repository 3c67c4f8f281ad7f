// Per-yarn fiber tables in the fiber-level ray trace (fabric_raytrace.h, FiberTables): a two-colour
// cloth lies between its colours, one table mapped everywhere is the single-table trace bit for
// bit, and bad maps and tables are refused by name.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "raytrace_test_util.h"
#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_fibers.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/fiber/thread_colour.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

// A "fiber" whose every point sends albedo[c] of what its fiber intercepts into its outer
// hemisphere, uniformly (f = albedo / (2 pi)): lossless at albedo 1, as the uniform fiber of
// test_fabric_raytrace.cpp.
TabulatedBsdfTable coloured_fiber(int resolution, std::array<double, 3> albedo) {
  auto t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3&, std::span<double> v) {
        for (int c = 0; c < 3; ++c) v[c] = wo.z > 0 ? albedo[c] * 0.5 * kInvPi : 0.0;
      },
      2, 1);
  t.kind = "fiber";
  return t;
}

// The bundled red-cotton sample (a plain weave) at yarn or fiber detail.
using weft::testing::default_sample;

FabricRaytraceOptions options(uint64_t particles_per_bin) {
  FabricRaytraceOptions o;
  o.resolution = 2;
  o.particles_per_bin = particles_per_bin;
  o.threads = 2;
  return o;
}

// Red warp, grey weft: the cloth's albedo in every channel lies strictly between the all-red and
// the all-grey cloth's, well inside (each direction shows about half of the cloth).
void expect_two_colour_cloth_between(const char* detail, uint64_t particles) {
  const WovenSample sample = default_sample(detail);
  const auto red = coloured_fiber(4, {0.9, 0.2, 0.2}), grey = coloured_fiber(4, {0.6, 0.6, 0.6});
  const FabricRaytraceOptions o = options(particles);
  const auto all_red = raytrace_fabric_table(sample, red, o).table.total_albedo();
  const auto all_grey = raytrace_fabric_table(sample, grey, o).table.total_albedo();
  const auto mixed_run =
      raytrace_fabric_table(sample, fiber_tables_by_direction(sample, red, grey), o);
  const auto mixed = mixed_run.table.total_albedo();
  for (int c = 0; c < 3; ++c) {
    const double lo = std::min(all_red[c], all_grey[c]), hi = std::max(all_red[c], all_grey[c]);
    // The all-red and all-grey cloths differ by far more than the noise (relative noise of a table
    // traced with these particles: ~1e-2 per cell, far less in the albedo summed over cells).
    ASSERT_GT(hi - lo, 0.05) << detail << " channel " << c;
    EXPECT_GT(mixed[c], lo + 0.15 * (hi - lo)) << detail << " channel " << c;
    EXPECT_LT(mixed[c], hi - 0.15 * (hi - lo)) << detail << " channel " << c;
  }
  // The red warp shows: red above green (the grey weft alone has them equal).
  EXPECT_GT(mixed[0] / mixed[1], 1.1) << detail;
  EXPECT_GT(mixed_run.table.metadata.count("fiber_tables"), 0u);
  if (std::string(detail) == "fiber") {
    size_t warps = 0;
    for (const std::string& m : sample.fibers.yarn_material) warps += m == "warp";
    EXPECT_EQ(
        mixed_run.table.metadata.at("fiber_yarns_per_table"),
        std::to_string(warps) + "," + std::to_string(sample.fibers.yarn_material.size() - warps));
  } else {
    EXPECT_EQ(mixed_run.table.metadata.at("fiber_table_of_mesh"), "0,1");  // warp, weft
  }
  EXPECT_EQ(mixed_run.table.metadata.count("fiber_checksum"), 0u);
}

}  // namespace

TEST(FiberTables, TwoColourYarnClothLiesBetweenItsColours) {
  expect_two_colour_cloth_between("yarn", 2000);
}

TEST(FiberTables, TwoColourFiberClothLiesBetweenItsColours) {
  expect_two_colour_cloth_between("fiber", 300);
}

// A two-colour draft shows its pattern in the weave table (the weave level's close-up) while its
// fabric table is the mixed colour: on the poplin (plain weave) with a red warp and a grey weft,
// lit from straight above, the light reflected straight back is greener, relative to red, over the
// position cells where a grey weft yarn is on top than over those where a red warp yarn is. The
// yarn on top of a cell is the one a ray from above meets at the cell's centre (the weave table's
// cell convention, weave_tally.h: u along x from the repeat's least x, v along -z from its
// greatest z). Expected ratio: the grey yarn's G/R albedo over the red one's, 1 / 0.22, diluted by
// light that scattered between the yarns; the test asks for 2.
TEST(FiberTables, TwoColourDraftShowsItsPatternInTheWeaveTable) {
  const WovenSample sample = default_sample("yarn");
  const auto red = coloured_fiber(4, {0.9, 0.2, 0.2}), grey = coloured_fiber(4, {0.6, 0.6, 0.6});
  constexpr int kR = 3, kPositions = 8;  // odd R: a bin centred on the normal
  const DirectionGrid grid{kR};
  const int up = grid.bin_of({0, 0, 1});
  FabricRaytraceOptions o = options(40000);
  o.resolution = kR;
  o.first_bin = up;
  o.bin_count = 1;
  o.weave_positions_u = o.weave_positions_v = kPositions;
  o.weave_resolution = kR;
  const auto run = raytrace_fabric_table(sample, fiber_tables_by_direction(sample, red, grey), o);
  const WeaveTable& w = run.weave;
  ASSERT_EQ(w.positions(), kPositions * kPositions);
  const raytrace::RepeatSlab r = raytrace::repeat_slab_of(sample);
  const RenderScene scene(raytrace::tiled_geometry(sample));
  double ratio_sum[2] = {0, 0};
  int cells[2] = {0, 0};  // [0]: a warp yarn on top, [1]: a weft yarn
  for (int iv = 0; iv < kPositions; ++iv)
    for (int iu = 0; iu < kPositions; ++iu) {
      const double fu = (iu + 0.5) / kPositions, fv = (iv + 0.5) / kPositions;
      SurfaceHit h;
      ASSERT_TRUE(scene.intersect(
          {{r.x0 + r.px * fu, r.y1 + 1e-6, r.z0 + r.pz - r.pz * fv}, {0, -1, 0}, 1e300}, &h));
      ASSERT_FALSE(h.on_fiber());
      const int k = sample.meshes.at(h.shape).material == "warp" ? 0 : 1;
      const int pos = iv * kPositions + iu;
      ratio_sum[k] += w.modulation[w.index(pos, up, up, 1)] / w.modulation[w.index(pos, up, up, 0)];
      ++cells[k];
    }
  ASSERT_GE(cells[0], 8);
  ASSERT_GE(cells[1], 8);
  const double warp_top = ratio_sum[0] / cells[0], weft_top = ratio_sum[1] / cells[1];
  EXPECT_GT(weft_top, 2.0 * warp_top) << "warp on top " << warp_top << ", weft " << weft_top;
}

TEST(FiberTables, EqualTablesAreTheSingleTableTraceBitForBit) {
  // Two table objects of equal values (one checksum) are one table: the same bits and metadata as
  // the single-table call, at both details.
  for (const char* detail : {"yarn", "fiber"}) {
    const WovenSample sample = default_sample(detail);
    const auto a = coloured_fiber(4, {0.9, 0.2, 0.2}), b = coloured_fiber(4, {0.9, 0.2, 0.2});
    const FabricRaytraceOptions o = options(200);
    const auto single = raytrace_fabric_table(sample, a, o);
    const auto per_yarn = raytrace_fabric_table(sample, fiber_tables_by_direction(sample, a, b), o);
    EXPECT_EQ(per_yarn.table.values, single.table.values) << detail;
    EXPECT_EQ(per_yarn.table.metadata, single.table.metadata) << detail;
    EXPECT_EQ(per_yarn.standard_error, single.standard_error) << detail;
  }
}

TEST(FiberTables, EveryYarnOnTheSecondTableIsThatTablesTraceBitForBit) {
  // Two distinct tables, every yarn mapped to the second: the per-yarn path looks each hit's table
  // up (the next-event draws' too), and none of the first table's values may leak into the trace.
  for (const char* detail : {"yarn", "fiber"}) {
    const WovenSample sample = default_sample(detail);
    const auto red = coloured_fiber(4, {0.9, 0.2, 0.2}), grey = coloured_fiber(4, {0.6, 0.6, 0.6});
    FiberTables f = fiber_tables_by_direction(sample, red, grey);
    for (int& k : f.table_of_yarn) k = 1;
    for (int& k : f.table_of_mesh) k = 1;
    for (const int next_event_rays : {0, 2}) {
      FabricRaytraceOptions o = options(200);
      o.next_event_rays = next_event_rays;
      EXPECT_EQ(raytrace_fabric_table(sample, f, o).table.values,
                raytrace_fabric_table(sample, grey, o).table.values)
          << detail << " next-event rays " << next_event_rays;
    }
  }
}

TEST(FiberTables, BadTablesAndMapsAreRefusedByName) {
  const WovenSample sample = default_sample("yarn");
  const auto red = coloured_fiber(4, {0.9, 0.2, 0.2}), coarse = coloured_fiber(2, {0.5, 0.5, 0.5});
  const FabricRaytraceOptions o = options(10);
  auto message = [&](const FiberTables& f, const FabricRaytraceOptions& opt) {
    try {
      raytrace_fabric_table(sample, f, opt);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Resolution differs: names the table and says why.
  EXPECT_NE(message(fiber_tables_by_direction(sample, red, coarse), o)
                .find("fiber tables[1] (weft)': has resolution 2"),
            std::string::npos);
  // A map that does not fit the sample, or indexes no table.
  FiberTables f = fiber_tables_by_direction(sample, red, red);
  f.table_of_mesh.push_back(0);
  EXPECT_NE(message(f, o).find("table_of_mesh"), std::string::npos);
  f = fiber_tables_by_direction(sample, red, red);
  f.table_of_mesh[1] = 2;
  EXPECT_NE(message(f, o).find("table_of_mesh[1]"), std::string::npos);
  // A table that is not a fiber's.
  auto fabric = red;
  fabric.kind = "fabric";
  EXPECT_NE(message(fiber_tables_by_direction(sample, red, fabric), o).find("expected a fiber"),
            std::string::npos);
  // An energy-creating table, by its name.
  const auto bright = coloured_fiber(4, {1.5, 1.5, 1.5});
  EXPECT_NE(message(fiber_tables_by_direction(sample, red, bright), o)
                .find("fiber tables[1] (weft)': the fiber table's total albedo"),
            std::string::npos);
  // The likelihood-ratio proposal takes one table.
  const auto grey = coloured_fiber(4, {0.6, 0.6, 0.6});
  FabricRaytraceOptions with_proposal = o;
  with_proposal.proposal = &red;
  EXPECT_NE(message(fiber_tables_by_direction(sample, red, grey), with_proposal).find("proposal"),
            std::string::npos);
  // No tables at all.
  EXPECT_NE(message(FiberTables{}, o).find("takes 1 to"), std::string::npos);
}

// A spec's fabric fiber table: a dye's measured absorption leaves the sRGB gamut (the RGB table
// of the bundled red cotton has negative values, FiberTableBake.RgbTableOfASaturatedDyeWarns...),
// so a dyed spec is baked by band; undyed and thread-coloured fibers, whose absorbers are smooth
// and inside the gamut by construction (docs/fabric-bsdf.md), stay RGB.
TEST(FiberTables, DyedSpecsAreBakedSpectralAndUndyedOnesRgb) {
  EXPECT_TRUE(fabric_fiber_bake_options(load_fiber_spec("red-cotton")).spectral);
  const FiberSpec white = load_fiber_spec("white-cotton");
  EXPECT_FALSE(fabric_fiber_bake_options(white).spectral);
  EXPECT_FALSE(
      fabric_fiber_bake_options(thread_colour_spec(white, {0.6, 0.1, 0.1}, "--thread-colours"))
          .spectral);
  // Everything else is the bake's defaults for the spec.
  FiberTableBakeOptions defaults = fiber_bake_defaults(white);
  const FiberTableBakeOptions o = fabric_fiber_bake_options(white);
  EXPECT_EQ(o.resolution, defaults.resolution);
  EXPECT_EQ(o.photons_per_band, defaults.photons_per_band);
}
