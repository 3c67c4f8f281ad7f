// A fabric table's sheen over half vectors (materials/half_vector_lobe.h): its energy against the
// window's projected area, its cell averages against an independent midpoint rule, and its place
// in the table file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/half_vector_lobe.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

HalfVectorLobe random_lobe(int resolution, int h_resolution, int window, int channels,
                           uint64_t seed) {
  HalfVectorLobe l = HalfVectorLobe::zeros(resolution, h_resolution, window, channels);
  Rng rng(seed, 0, 0);
  for (float& v : l.values) v = static_cast<float>(rng.uniform());
  return l;
}

// The midpoint rule of int g(d) |cos theta| d omega over the upper hemisphere on the equal-area
// chart at resolution n (each bin 2 pi / n^2).
template <class G>
double upper_integral(int n, G&& g) {
  const DirectionGrid grid{n};
  double sum = 0;
  for (int k = 0; k < n * n; ++k) {
    const Vec3 d = grid.bin_center(k);
    sum += g(d) * d.z;
  }
  return sum * grid.bin_solid_angle();
}

}  // namespace

TEST(HalfVectorLobe, WindowBinsAndTheirPointsAgree) {
  const HalfVectorLobe l = HalfVectorLobe::zeros(2, 16, 6, 3);
  for (int k = 0; k < l.window_bins(); ++k) {
    const Vec3 h = l.window_point(k, 0.5, 0.5);
    EXPECT_EQ(l.window_bin_of(h), k);
    EXPECT_EQ(l.window_bin_of({h.x, h.y, -h.z}), k);  // the lower face's, mirrored
  }
  EXPECT_GE(l.window_bin_of({0, 0, 1}), 0);                    // the pole is in the window
  EXPECT_EQ(l.window_bin_of(normalize(Vec3{1, 0, 0.2})), -1);  // far from the pole
}

// With Q = q everywhere, light along the normal leaves with int f cos_o d wo = q int_window h.z
// d h = q times the window bins' cosine-weighted areas on the half vectors' grid (from f cos_o
// d wo = Q (wi . h) / cos_i d h, d wo = 4 (wo . h) d h: Walter et al., "Microfacet Models for
// Refraction through Rough Surfaces", EGSR 2007, eq. 14).
TEST(HalfVectorLobe, NormalLightReflectsTheWindowsProjectedArea) {
  const double q = 0.8;
  HalfVectorLobe l = HalfVectorLobe::zeros(4, 16, 8, 3);
  for (float& v : l.values) v = static_cast<float>(q);
  const auto d = DirectionGrid{16}.cosine_weighted_areas();
  double window_area = 0;
  for (int k = 0; k < l.window_bins(); ++k) {
    const int bin = DirectionGrid{16}.bin_of(l.window_point(k, 0.5, 0.5));
    window_area += d[static_cast<size_t>(bin)];
  }
  std::vector<double> f(3);
  const double albedo = upper_integral(512, [&](const Vec3& wo) {
    l.eval(wo, {0, 0, 1}, f);
    return f[1];
  });
  EXPECT_NEAR(albedo, q * window_area, 0.005 * q * window_area);
  // Nothing below the light's side, nothing from the other side.
  l.eval({0.1, 0, -1}, {0, 0, 1}, f);
  EXPECT_EQ(f[0], 0.0);
  l.eval({0, 0, 1}, {0, 0, -1}, f);
  EXPECT_EQ(f[2], 0.0);
}

// cell_averages against the midpoint rule of eval itself: 12 x 12 wi per light bin, 48 x 48 wo per
// exit bin, each weighted by its |cos theta| (shares nothing with the quadrature but eval).
TEST(HalfVectorLobe, CellAveragesMatchAMidpointRuleOfEval) {
  const HalfVectorLobe l = random_lobe(2, 16, 8, 3, 7);
  const DirectionGrid grid{2};
  const auto cells = l.cell_averages(2);
  const int bins = grid.bins(), ni = 12, no = 48;
  std::vector<double> f(3);
  double worst = 0, largest = 0;
  for (int a = 0; a < bins; ++a)
    for (int b = 0; b < bins; ++b) {
      double sum = 0, wsum = 0;
      for (int i = 0; i < ni * ni; ++i) {
        const Vec3 wi = DirectionGrid::to_direction(
            grid.chart_point(a, (i % ni + 0.5) / ni, (i / ni + 0.5) / ni));
        for (int o = 0; o < no * no; ++o) {
          const Vec3 wo = DirectionGrid::to_direction(
              grid.chart_point(b, (o % no + 0.5) / no, (o / no + 0.5) / no));
          const double w = std::abs(wi.z) * std::abs(wo.z);
          l.eval(wo, wi, f);
          sum += f[0] * w;
          wsum += w;
        }
      }
      const double expected = sum / wsum, got = cells[(static_cast<size_t>(a) * bins + b) * 3];
      worst = std::max(worst, std::abs(got - expected));
      largest = std::max(largest, expected);
      if (grid.upper(a) != grid.upper(b)) EXPECT_EQ(got, 0.0) << a << " " << b;
    }
  ASSERT_GT(largest, 0.0);
  EXPECT_LT(worst, 0.01 * largest);
}

TEST(HalfVectorLobe, AddedAndRemovedLeavesTheCells) {
  TabulatedBsdfTable t;
  t.resolution = 2, t.channels = 3, t.kind = "fabric";
  t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * 3, 0.25f);
  const TabulatedBsdfTable before = t;
  t.add_sheen(random_lobe(2, 16, 8, 3, 3));
  ASSERT_TRUE(t.sheen);
  EXPECT_NE(t.checksum(), before.checksum());
  const TabulatedBsdfTable rest = t.without_sheen("t.exr");
  EXPECT_FALSE(rest.sheen);
  for (size_t k = 0; k < rest.values.size(); ++k)
    EXPECT_NEAR(rest.values[k], before.values[k], 1e-6) << k;
  EXPECT_THROW(t.add_sheen(random_lobe(2, 16, 8, 3, 3)), Error);
  // Cells holding less than their sheen were not made by adding it.
  TabulatedBsdfTable bad = before;
  bad.sheen = random_lobe(2, 16, 8, 3, 3);
  for (float& v : bad.values) v = 0;
  EXPECT_THROW(bad.without_sheen("bad.exr"), Error);
}

TEST(HalfVectorLobe, TheTableFileKeepsItBitForBit) {
  const fs::path dir = fresh_test_dir();
  TabulatedBsdfTable t;
  t.resolution = 2, t.channels = 3, t.kind = "fabric";
  t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * 3, 0.5f);
  t.add_sheen(random_lobe(2, 16, 8, 3, 5));
  const fs::path path = dir / "sheen.exr";
  t.write_exr(path);
  const TabulatedBsdfTable back = TabulatedBsdfTable::read_exr(path);
  ASSERT_TRUE(back.sheen);
  EXPECT_EQ(back.values, t.values);
  EXPECT_EQ(back.sheen->values, t.sheen->values);
  EXPECT_EQ(back.sheen->h_resolution, 16);
  EXPECT_EQ(back.sheen->window, 8);
  EXPECT_EQ(back.checksum(), t.checksum());
  EXPECT_TRUE(back.metadata.empty());
}

TEST(HalfVectorLobe, AMalformedHeaderNamesTheAttribute) {
  auto error_of = [](std::map<std::string, std::string> a) {
    try {
      HalfVectorLobe::from_attributes(a, 2, 3, "t.exr");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::map<std::string, std::string> good = HalfVectorLobe::zeros(2, 16, 8, 3).attributes();
  EXPECT_TRUE(HalfVectorLobe::from_attributes(good, 2, 3, "t.exr").has_value());
  EXPECT_FALSE(HalfVectorLobe::from_attributes({}, 2, 3, "t.exr").has_value());
  auto with = [&](const std::string& k, const std::string& v) {
    auto a = good;
    a[k] = v;
    return a;
  };
  EXPECT_NE(error_of(with("sheen_window", "5")).find("sheen_window"), std::string::npos);
  EXPECT_NE(error_of(with("sheen_window", "32")).find("sheen_window"), std::string::npos);
  EXPECT_NE(error_of(with("sheen_h_resolution", "1e9")).find("sheen_h_resolution"),
            std::string::npos);
  EXPECT_NE(error_of(with("sheen_h_resolution", "x")).find("sheen_h_resolution"),
            std::string::npos);
  EXPECT_NE(error_of(with("sheen", "tensor")).find("sheen"), std::string::npos);
  auto orphan = good;
  orphan.erase("sheen");
  EXPECT_NE(error_of(orphan).find("given without"), std::string::npos);
}
