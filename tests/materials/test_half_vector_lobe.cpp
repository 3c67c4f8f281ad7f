// A fabric table's sheen over half vectors (materials/half_vector_lobe.h): its energy against the
// window's projected area, its cell averages against an independent midpoint rule, and its place
// in the table file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/fresnel.h"
#include "weft/materials/half_vector_lobe.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

HalfVectorLobe random_lobe(int resolution, int h_resolution, int window, int channels,
                           uint64_t seed, int light_resolution = 0) {
  HalfVectorLobe l =
      HalfVectorLobe::zeros(resolution, h_resolution, window, channels, light_resolution);
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

void cell_averages_match_midpoint_rule(const HalfVectorLobe& l);

}  // namespace

// An even grid's window has the pole at its central corner, an odd one's at its central bin's
// centre (where a peak about the pole is not split four ways).
TEST(HalfVectorLobe, WindowBinsAndTheirPointsAgree) {
  for (const auto& [h_resolution, window] : {std::pair{16, 6}, std::pair{17, 5}}) {
    const HalfVectorLobe l = HalfVectorLobe::zeros(2, h_resolution, window, 3);
    for (int k = 0; k < l.window_bins(); ++k) {
      const Vec3 h = l.window_point(k, 0.5, 0.5);
      EXPECT_EQ(l.window_bin_of(h), k);
      EXPECT_EQ(l.window_bin_of({h.x, h.y, -h.z}), k);  // the lower face's, mirrored
    }
    EXPECT_GE(l.window_bin_of({0, 0, 1}), 0);                    // the pole is in the window
    EXPECT_EQ(l.window_bin_of(normalize(Vec3{1, 0, 0.2})), -1);  // far from the pole
    if (window % 2) {
      const Vec3 centre = l.window_point(window * window / 2, 0.5, 0.5);
      EXPECT_NEAR(centre.z, 1.0, 1e-12) << h_resolution;
    }
  }
  EXPECT_THROW(HalfVectorLobe::zeros(2, 17, 6, 3), Error);  // not centred on the pole
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
// With and without the Fresnel factor, which both must apply alike.
TEST(HalfVectorLobe, CellAveragesMatchAMidpointRuleOfEval) {
  for (int light_resolution : {2, 4})
    for (double ior : {0.0, 1.6}) {
      if (light_resolution == 4 && ior == 0) continue;  // the finer grid's blend, once
      SCOPED_TRACE(light_resolution);
      HalfVectorLobe l = random_lobe(2, 16, 8, 3, 7, light_resolution);
      l.fresnel_ior = ior;
      cell_averages_match_midpoint_rule(l);
    }
}

// The light bins of R_l = m R nest in the table's: light bin b is kept in its table bin's m^2
// slots (the table bin holds b's centre), each slot holds one light bin, and a light bin's mean
// projection is its share of the table bin's quadrature (the m^2 of them average to it).
TEST(HalfVectorLobe, FinerLightBinsNestInTheTablesBins) {
  const HalfVectorLobe coarse = HalfVectorLobe::zeros(2, 16, 6, 3);
  const std::vector<double> whole = coarse.mean_projections(2);
  for (int light_resolution : {4, 8}) {
    const HalfVectorLobe l = HalfVectorLobe::zeros(2, 16, 6, 3, light_resolution);
    const int m2 = l.light_bins_per_cell(), n = l.light_grid().bins();
    ASSERT_EQ(n, DirectionGrid{2}.bins() * m2);
    ASSERT_EQ(l.values.size(), static_cast<size_t>(n) * l.window_bins() * 3);
    std::vector<int> seen(static_cast<size_t>(n), 0);
    for (int b = 0; b < n; ++b) {
      const size_t s = l.slot(b);
      ASSERT_LT(s, static_cast<size_t>(n));
      ++seen[s];
      EXPECT_EQ(l.light_bin_at(s), b);
      EXPECT_EQ(static_cast<int>(s) / m2, DirectionGrid{2}.bin_of(l.light_grid().bin_center(b)))
          << light_resolution << " " << b;
    }
    for (int c : seen) EXPECT_EQ(c, 1);
    const std::vector<double> fine = l.mean_projections(2);
    const size_t nk = static_cast<size_t>(l.window_bins());
    for (size_t a = 0; a < whole.size() / nk; ++a)
      for (size_t k = 0; k < nk; ++k) {
        double mean = 0;
        for (size_t j = 0; j < static_cast<size_t>(m2); ++j) mean += fine[(a * m2 + j) * nk + k];
        EXPECT_NEAR(mean / m2, whole[a * nk + k], 1e-12) << light_resolution << " " << a;
      }
  }
}

namespace {
void cell_averages_match_midpoint_rule(const HalfVectorLobe& l) {
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
      if (grid.upper(a) != grid.upper(b)) {
        EXPECT_EQ(got, 0.0) << a << " " << b;
      }
    }
  ASSERT_GT(largest, 0.0) << l.fresnel_ior;
  EXPECT_LT(worst, 0.01 * largest) << l.fresnel_ior;
}
}  // namespace

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
  for (int light_resolution : {2, 4, 8}) {
    TabulatedBsdfTable t;
    t.resolution = 2, t.channels = 3, t.kind = "fabric";
    t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * 3, 0.5f);
    HalfVectorLobe lobe = random_lobe(2, 16, 8, 3, 5, light_resolution);
    lobe.fresnel_ior = 1.5700000000000001;
    t.add_sheen(lobe);
    const fs::path path = dir / ("sheen" + std::to_string(light_resolution) + ".exr");
    t.write_exr(path);
    const TabulatedBsdfTable back = TabulatedBsdfTable::read_exr(path);
    ASSERT_TRUE(back.sheen);
    EXPECT_EQ(back.values, t.values);
    EXPECT_EQ(back.sheen->values, t.sheen->values);
    EXPECT_EQ(back.sheen->h_resolution, 16);
    EXPECT_EQ(back.sheen->window, 8);
    EXPECT_EQ(back.sheen->fresnel_ior, lobe.fresnel_ior);
    EXPECT_EQ(back.sheen->light_resolution, light_resolution);
    EXPECT_EQ(back.checksum(), t.checksum());
    EXPECT_TRUE(back.metadata.empty());
  }
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
  // The Fresnel index: 0 (none) or in (1, 4].
  for (const char* bad : {"0.9", "1", "4.5", "nan", "x"})
    EXPECT_NE(error_of(with("sheen_fresnel_ior", bad)).find("sheen_fresnel_ior"), std::string::npos)
        << bad;
  EXPECT_EQ(
      HalfVectorLobe::from_attributes(with("sheen_fresnel_ior", "1.5"), 2, 3, "t.exr")->fresnel_ior,
      1.5);
  // Before format 6 such an attribute was another program's: ignored.
  EXPECT_EQ(HalfVectorLobe::from_attributes(with("sheen_fresnel_ior", "x"), 2, 3, "t.exr", 5)
                ->fresnel_ior,
            0.0);
  // The light bins nest in the table's (R 2 here): 2, 4 or 8, the table's when absent.
  for (const char* bad : {"1", "3", "6", "16", "0", "-4", "2.5", "x"})
    EXPECT_NE(error_of(with("sheen_light_resolution", bad)).find("sheen_light_resolution"),
              std::string::npos)
        << bad;
  EXPECT_EQ(HalfVectorLobe::from_attributes(good, 2, 3, "t.exr")->light_resolution, 2);
  EXPECT_EQ(HalfVectorLobe::from_attributes(with("sheen_light_resolution", "8"), 2, 3, "t.exr")
                ->light_resolution,
            8);
  // Before format 7: another program's, ignored.
  EXPECT_EQ(HalfVectorLobe::from_attributes(with("sheen_light_resolution", "x"), 2, 3, "t.exr", 6)
                ->light_resolution,
            2);
}

// A sheen whose Q is the fibers' Fresnel reflectance alone (D G = 1 over the window), booked per
// (light bin, window bin) as the fabric ray trace books it: the light of each, over the mean
// projection (mean_projections). Held over its Fresnel reflectance the values are 1 and eval is
// exact at any light; held as Q, the light bins' blend misses the fourfold rise of F from a 55 to
// a 75 degree light: the mirror's f is off by +3.5, +31, +87 and +40 % at 30, 45, 60 and 70
// degrees (measured 2026-12-06, R 8), while held over F it is within 1 %.
TEST(HalfVectorLobe, HeldOverItsFresnelAGrazingLightsSheenStaysTrue) {
  constexpr double kIor = 1.57;  // polyester (docs/presets.md)
  constexpr int kR = 8, kWiSide = 8, kHSide = 3;
  HalfVectorLobe plain = HalfVectorLobe::zeros(kR, 32, 8, 3), fresnel = plain;
  fresnel.fresnel_ior = kIor;
  const DirectionGrid grid{kR};
  const size_t nk = static_cast<size_t>(plain.window_bins());
  // The light each (light bin, window bin) books, per particle and window bin solid angle: the
  // mean of Q (wi . h) over the bin pair, wo on wi's side (the booking's own quadrature is finer).
  std::vector<double> light(static_cast<size_t>(grid.bins()) * nk, 0.0);
  for (int a = 0; a < grid.bins(); ++a)
    for (int i = 0; i < kWiSide * kWiSide; ++i) {
      const Vec3 wi = DirectionGrid::to_direction(
          grid.chart_point(a, (i % kWiSide + 0.5) / kWiSide, (i / kWiSide + 0.5) / kWiSide));
      for (size_t k = 0; k < nk; ++k)
        for (int j = 0; j < kHSide * kHSide; ++j) {
          Vec3 h = plain.window_point(static_cast<int>(k), (j % kHSide + 0.5) / kHSide,
                                      (j / kHSide + 0.5) / kHSide);
          if (wi.z < 0) h.z = -h.z;
          const double wi_h = dot(wi, h);
          if (!(wi_h > 0) || !((2 * wi_h * h - wi).z * wi.z > 0)) continue;
          light[static_cast<size_t>(a) * nk + k] +=
              fresnel_dielectric(wi_h, 1, kIor) * wi_h / (kWiSide * kWiSide * kHSide * kHSide);
        }
    }
  for (HalfVectorLobe* l : {&plain, &fresnel}) {
    const std::vector<double> m = l->mean_projections(2);
    for (size_t v = 0; v < l->values.size(); ++v)
      l->values[v] = m[v / 3] > 0 ? static_cast<float>(light[v / 3] / m[v / 3]) : 0.0f;
  }
  std::vector<double> f(3);
  double worst_plain = 0;
  for (double theta_deg : {30.0, 45.0, 60.0, 70.0}) {
    const double t = deg_to_rad(theta_deg);
    const Vec3 wi{std::sin(t), 0, std::cos(t)}, wo{-std::sin(t), 0, std::cos(t)};
    const double truth = fresnel_dielectric(std::cos(t), 1, kIor) / (4 * wi.z * wo.z);
    fresnel.eval(wo, wi, f);
    EXPECT_NEAR(f[1], truth, 0.01 * truth) << theta_deg;
    plain.eval(wo, wi, f);
    worst_plain = std::max(worst_plain, std::abs(f[1] / truth - 1));
    std::printf("%.0f deg: held as Q %+.1f %%\n", theta_deg, 100 * (f[1] / truth - 1));
  }
  EXPECT_GT(worst_plain, 0.1);  // what holding it over F mends
}
