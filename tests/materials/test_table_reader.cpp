// A table read as the renderer reads it (materials/table_reader.h): without a sheen the cells
// interpolated, bit for bit; with one the rest interpolated plus the sheen, which keeps a peak the
// cells blur, agrees with the renderer's TabulatedBsdf, and reduces to RGB like the cells.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gaussian_sheen.h"
#include "rgb_table.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/materials/table_compare.h"
#include "weft/materials/table_inplane.h"
#include "weft/materials/table_reader.h"
#include "weft/materials/tabulated_bsdf.h"

// A named namespace: the unity build puts this file in one batch with others.
namespace weft::table_reader_test {

using testing::gaussian_sheen;
using testing::rgb_table;

// Cells 0.05 / sr with light and view on one side, 0.01 / sr through the cloth.
TabulatedBsdfTable plain_fabric(int resolution, int channels) {
  TabulatedBsdfTable t;
  t.resolution = resolution, t.channels = channels, t.kind = "fabric";
  const int n = t.bins();
  const DirectionGrid g = t.grid();
  t.values.resize(static_cast<size_t>(n) * n * channels);
  for (int i = 0; i < n; ++i)
    for (int o = 0; o < n; ++o)
      for (int c = 0; c < channels; ++c)
        t.values[t.index(i, o, c)] = g.upper(i) == g.upper(o) ? 0.05f : 0.01f;
  return t;
}

// The view mirroring 'wi' about the normal.
Vec3 mirror(const Vec3& wi) {
  return {-wi.x, -wi.y, wi.z};
}

TEST(TableReader, ATableWithoutSheenReadsAsItsInterpolationBitForBit) {
  Rng rng(5, 0, 0);
  const TabulatedBsdfTable t = rgb_table(4, [&](const Vec3& wo, const Vec3& wi) {
    return Rgb(1.1 + wo.z * wi.z, 1.2 + wo.x, 0.3 + wi.y * wi.y);
  });
  const TableReader r(t);
  const TableReader copy = r;
  EXPECT_EQ(&r.cells(), &t);  // not copied
  EXPECT_EQ(r.sheen(), nullptr);
  std::vector<double> a(3), b(3), c(3);
  for (int k = 0; k < 500; ++k) {
    const Vec3 wo = spherical_direction(std::acos(2 * rng.uniform() - 1), 2 * kPi * rng.uniform());
    const Vec3 wi = spherical_direction(std::acos(2 * rng.uniform() - 1), 2 * kPi * rng.uniform());
    t.interpolate(wo, wi, a);
    r.eval(wo, wi, b);
    copy.eval(wo, wi, c);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_EQ(a[ch], b[ch]) << wo << wi;
      EXPECT_EQ(a[ch], c[ch]) << wo << wi;
    }
  }
}

// A peak 3 degrees wide in the half vector, about 1 / sr high at the mirror of 30 degrees: the
// reader holds it (the rest's 0.05 plus the sheen, to float rounding of the cells) at the mirror
// and 20 degrees off it, where the sheen has fallen below 2 % of its peak; the cells alone (an
// R 8 table, bins about 18 degrees across) read at most 0.3 of it at the mirror (measured: 0.26
// of it at 30 degrees, 0.13 at 45, 0.15 at 60).
TEST(TableReader, ASheenIsReadSharpWhereTheCellsBlurIt) {
  TabulatedBsdfTable t = plain_fabric(8, 3);
  const HalfVectorLobe sheen = gaussian_sheen(8, 3, 3.0, 3.0);
  t.add_sheen(sheen);
  const TableReader r(t);
  ASSERT_NE(r.sheen(), nullptr);
  EXPECT_FALSE(r.cells().sheen);
  std::vector<double> f(3), cells(3), s(3), s_off(3);
  for (double deg : {30.0, 45.0, 60.0}) {
    const Vec3 wi = spherical_direction(deg_to_rad(deg), 0.4), wo = mirror(wi);
    sheen.eval(wo, wi, s);
    ASSERT_GT(s[1], 0.5);
    r.eval(wo, wi, f);
    EXPECT_NEAR(f[1], 0.05 + s[1], 1e-6) << deg;
    t.interpolate(wo, wi, cells);
    std::printf("%g deg: sheen %.3f, read %.3f, cells alone %.3f above the rest\n", deg, s[1], f[1],
                cells[1] - 0.05);
    EXPECT_LT(cells[1] - 0.05, 0.3 * s[1]) << deg;
    const Vec3 off = spherical_direction(deg_to_rad(deg - 20), 0.4 + kPi);
    sheen.eval(off, wi, s_off);
    EXPECT_LT(s_off[1], 0.02 * s[1]) << deg;
    r.eval(off, wi, f);
    EXPECT_NEAR(f[1], 0.05 + s_off[1], 1e-6) << deg;
  }
}

// The reader reads what the renderer evaluates (TabulatedBsdf::eval, interpolated lookup).
TEST(TableReader, ReadsWhatTheRendererEvaluates) {
  TabulatedBsdfTable t = rgb_table(
      4, [](const Vec3& wo, const Vec3& wi) { return Rgb(wo.z * wi.z > 0 ? 0.1 : 0.02); });
  t.kind = "fabric";
  t.add_sheen(gaussian_sheen(4, 3, 2.0, 6.0, 32, 8));
  const TableReader r(t);
  const TabulatedBsdf b{TabulatedBsdfData::prepare(t), Rgb(1.0)};
  std::vector<double> f(3);
  for (double deg : {10.0, 35.0, 70.0})
    for (double off : {0.0, 0.03, 0.2}) {
      const Vec3 wi = spherical_direction(deg_to_rad(deg), 1.1);
      const Vec3 wo = normalize(mirror(wi) + Vec3{off, 0, 0});
      r.eval(wo, wi, f);
      const Rgb e = b.eval(wo, wi);
      EXPECT_NEAR(f[0], e.r, 1e-6 * e.r) << deg << " " << off;
      EXPECT_NEAR(f[2], e.b, 1e-6 * e.b) << deg << " " << off;
    }
}

// A spectral reader reduced to RGB (table_to_rgb): the reduced f is the reduction of the read f
// (the reduction is linear), and the sheen is kept.
TEST(TableReader, ReducedToRgbIsTheReductionOfTheRead) {
  TabulatedBsdfTable t = plain_fabric(4, kNumBands);
  for (size_t k = 0; k < t.values.size(); ++k)
    t.values[k] *= static_cast<float>(0.5 + static_cast<double>(k % kNumBands) / kNumBands);
  t.add_sheen(gaussian_sheen(4, kNumBands, 2.0, 6.0, 32, 8));
  const TableReader r(t);
  const TableReader rgb = table_to_rgb(r);
  ASSERT_EQ(rgb.channels(), 3);
  ASSERT_NE(rgb.sheen(), nullptr);
  std::vector<double> bands(kNumBands), f(3);
  for (double deg : {20.0, 50.0})
    for (double off : {0.0, 0.3}) {
      const Vec3 wi = spherical_direction(deg_to_rad(deg), 0.2);
      const Vec3 wo = normalize(mirror(wi) + Vec3{off, 0, 0});
      r.eval(wo, wi, bands);
      rgb.eval(wo, wi, f);
      const Rgb e = bands_to_linear_srgb([&](int b) { return bands[static_cast<size_t>(b)]; });
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(f[static_cast<size_t>(c)], e[c], 1e-5 * std::abs(e[c]) + 1e-7) << deg;
    }
}

// weft compare reads both tables with their sheens: a table and its cells alone (the sheen dropped,
// the cells the same) differ, in reflection and in the in-plane curves, and not in transmission,
// where the sheen sends nothing.
TEST(TableReader, CompareSeesTheSheen) {
  TabulatedBsdfTable with = plain_fabric(4, 3);
  with.add_sheen(gaussian_sheen(4, 3, 2.0, 6.0, 32, 8));
  TabulatedBsdfTable cells = with;
  cells.sheen.reset();
  const TableComparison c = compare_tables(with, cells);
  EXPECT_GT(c.reflection.rel_rms, 0.0);
  EXPECT_GT(c.in_plane_rel_rms, 0.0);
  EXPECT_EQ(c.transmission.rel_rms, 0.0);
  EXPECT_EQ(compare_tables(cells, cells).overall.rel_rms, 0.0);
}

}  // namespace weft::table_reader_test
