// The RGL .bsdf export read back by an independent reader (rgl_reader.h) and evaluated the way
// Mitsuba 3's and pbrt-v4's `measured` BSDFs evaluate it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <map>
#include <set>

#include "exchange_tables.h"
#include "gaussian_sheen.h"
#include "rgl_reader.h"
#include "test_util.h"
#include "weft/core/frame.h"
#include "weft/core/rng.h"
#include "weft/exchange/export_table.h"
#include "weft/exchange/table_view.h"
#include "weft/materials/table_reader.h"

namespace weft {
namespace {

using testing::RglEvaluator;

std::map<std::string, testing::RglField> export_and_read(const TabulatedBsdfTable& t,
                                                         const std::string& name) {
  const auto path = testing::fresh_test_dir() / name;
  ExportOptions o;
  o.name = "test";
  export_table(t, path, o);
  return testing::read_rgl(path);
}

// The hemispherical albedo of the export for one view, int f cos d omega_light, by the midpoint
// rule in (cos theta, phi) (64 x 128 points).
double export_albedo(const RglEvaluator& e, const Vec3& view, int c) {
  double sum = 0;
  for (int a = 0; a < 64; ++a)
    for (int b = 0; b < 128; ++b)
      sum += e.eval(view, spherical_direction(std::acos((a + 0.5) / 64), 2 * kPi * (b + 0.5) / 128),
                    c);
  return sum * (1.0 / 64) * (2 * kPi / 128);
}

TEST(RglBsdf, FieldsShapesAndTypesAreWhatMitsubaAndPbrtRequire) {
  auto f = export_and_read(testing::lambert_rgb(), "lambert.bsdf");
  std::set<std::string> names;
  for (const auto& [k, v] : f) names.insert(k);
  // Mitsuba 3 measured.cpp: an RGB file has 'rgb' and no 'wavelengths'.
  EXPECT_EQ(names, (std::set<std::string>{"description", "jacobian", "theta_i", "phi_i", "ndf",
                                          "sigma", "vndf", "luminance", "rgb"}));
  for (const char* n : {"theta_i", "phi_i", "ndf", "sigma", "vndf", "luminance", "rgb"})
    EXPECT_EQ(f.at(n).dtype, 10) << n;  // float32
  EXPECT_EQ(f.at("description").dtype, 1);
  EXPECT_EQ(f.at("jacobian").dtype, 1);
  EXPECT_EQ(f.at("jacobian").bytes, std::string(1, '\1'));
  EXPECT_EQ(f.at("ndf").shape.size(), 2u);
  EXPECT_EQ(f.at("sigma").shape.size(), 2u);
  const auto& lum = f.at("luminance").shape;
  const auto& rgb = f.at("rgb").shape;
  const auto& vndf = f.at("vndf").shape;
  ASSERT_EQ(lum.size(), 4u);
  ASSERT_EQ(rgb.size(), 5u);
  ASSERT_EQ(vndf.size(), 4u);
  EXPECT_EQ(vndf[0], f.at("phi_i").shape[0]);
  EXPECT_EQ(vndf[1], f.at("theta_i").shape[0]);
  EXPECT_EQ(lum[0], 1u);  // isotropic: phi_i has one value
  EXPECT_EQ(lum[1], f.at("theta_i").shape[0]);
  EXPECT_EQ(lum[2], lum[3]);
  EXPECT_EQ(rgb[2], 3u);
  EXPECT_EQ(rgb[3], lum[2]);
  EXPECT_EQ(rgb[4], lum[3]);
  for (const auto& [k, v] : f) EXPECT_EQ(v.offset % 8, 0u) << k;
  for (float x : f.at("rgb").f) EXPECT_GE(x, 0.0f);
}

TEST(RglBsdf, LambertianEvaluatesToRhoOverPiTimesCosine) {
  const RglEvaluator e(export_and_read(testing::lambert_rgb(), "lambert.bsdf"));
  const double rho[3] = {0.2, 0.5, 0.8};
  Rng rng(7);
  std::vector<double> rel;
  for (int n = 0; n < 3000; ++n) {
    // Up to 80 degrees either way; the exact answer rho / pi cos theta_light (exchange_tables.h).
    const Vec3 v =
        spherical_direction(std::acos(1 - 0.83 * rng.uniform()), 2 * kPi * rng.uniform());
    const Vec3 l =
        spherical_direction(std::acos(1 - 0.83 * rng.uniform()), 2 * kPi * rng.uniform());
    for (int c = 0; c < 3; ++c) rel.push_back(std::abs(e.eval(v, l, c) / (rho[c] / kPi * l.z) - 1));
  }
  std::sort(rel.begin(), rel.end());
  // The interpolation error of the 48 x 48 sample grid and the incidence angles: measured median
  // 0.24 %, 95th percentile 1.3 % (the largest, 35 %, at grazing light and view) with 21 angles
  // spaced as the paper spaces them and point values.
  EXPECT_LT(rel[rel.size() / 2], 0.01);
  EXPECT_LT(rel[rel.size() * 95 / 100], 0.05);
}

TEST(RglBsdf, LambertianAlbedoPerIncidenceMatchesTheTable) {
  const auto table = testing::lambert_rgb();
  const RglEvaluator e(export_and_read(table, "lambert.bsdf"));
  for (double deg : {0.0, 20.0, 45.0, 60.0, 75.0}) {
    const Vec3 v = spherical_direction(deg_to_rad(deg), 0.3);
    const auto a = table.directional_albedo_seen_from(table.grid().bin_of(v));
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(export_albedo(e, v, c), a.reflectance[static_cast<size_t>(c)],
                  0.02 * a.reflectance[static_cast<size_t>(c)])
          << deg << " deg, channel " << c;
  }
}

TEST(RglBsdf, SpectralTableWritesSpectraAndWavelengths) {
  const auto rho = testing::ramp_spectrum();
  auto f = export_and_read(testing::lambert_table(6, rho, std::vector<double>(33, 0.0)), "s.bsdf");
  ASSERT_TRUE(f.count("spectra") && f.count("wavelengths"));
  EXPECT_FALSE(f.count("rgb"));
  ASSERT_EQ(f.at("wavelengths").f.size(), 33u);
  EXPECT_EQ(f.at("wavelengths").f.front(), 390.0f);  // spectrum.h: band centres 390 + 10 i nm
  EXPECT_EQ(f.at("wavelengths").f.back(), 710.0f);
  EXPECT_EQ(f.at("spectra").shape[2], 33u);
  const RglEvaluator e(std::move(f));
  const Vec3 v = spherical_direction(deg_to_rad(30), 1.0),
             l = spherical_direction(deg_to_rad(40), 3.5);
  for (int b = 0; b < 33; b += 8)
    EXPECT_NEAR(e.eval(v, l, b), rho[static_cast<size_t>(b)] / kPi * l.z,
                0.05 * rho[static_cast<size_t>(b)] / kPi * l.z)
        << "band " << b;
}

TEST(RglBsdf, LobeTableAlbedoMatchesTheTable) {
  // The reference: the table's albedo towards the view as the table material evaluates it
  // (TabulatedBsdfTable::interpolate), integrated with the same rule as the export's and averaged
  // over the 16 view azimuths 2 pi k / 16 (the export is the table's average over those rotations,
  // rgl_bsdf.h; an interpolated table is not exactly isotropic).
  const auto table = testing::lobe_rgb();
  const RglEvaluator e(export_and_read(table, "lobe.bsdf"));
  for (double deg : {10.0, 40.0, 70.0}) {
    const Vec3 v = spherical_direction(deg_to_rad(deg), 0.0);
    double ref[3] = {0, 0, 0};
    std::vector<double> f(3);
    for (int k = 0; k < 16; ++k)
      for (int a = 0; a < 64; ++a)
        for (int b = 0; b < 128; ++b) {
          const double phi = 2 * kPi * (b + 0.5) / 128 + 2 * kPi * k / 16;
          const Vec3 l = spherical_direction(std::acos((a + 0.5) / 64), phi);
          table.interpolate(spherical_direction(deg_to_rad(deg), 2 * kPi * k / 16), l, f);
          for (int c = 0; c < 3; ++c)
            ref[c] += f[static_cast<size_t>(c)] * l.z / 64 * (2 * kPi / 128) / 16;
        }
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(export_albedo(e, v, c), ref[c], 0.02 * ref[c]) << deg << " deg, channel " << c;
  }
}

// The export's target: the table's f cos theta_light per channel, from the table's own
// reading (TableReader: the cells interpolated, plus the sheen of a table that holds one; what
// Weft's renderer evaluates), averaged over
// 64 rotations 2 pi k / 64 of both directions about the normal: the file is isotropic
// (rgl_bsdf.h), and the directions drawn here have any azimuth, so this stands for the table's
// mean over all rotations.
std::vector<double> table_f_cos(const TableReader& t, const Vec3& v, const Vec3& l) {
  constexpr int kTurns = 64;
  std::vector<double> f(static_cast<size_t>(t.channels())), sum(f.size(), 0.0);
  for (int k = 0; k < kTurns; ++k) {
    const double a = 2 * kPi * k / kTurns, ca = std::cos(a), sa = std::sin(a);
    auto turn = [&](const Vec3& w) { return Vec3{ca * w.x - sa * w.y, sa * w.x + ca * w.y, w.z}; };
    t.eval(turn(v), turn(l), f);
    for (size_t c = 0; c < f.size(); ++c) sum[c] += f[c];
  }
  for (double& x : sum) x *= l.z / kTurns;
  return sum;
}

// Relative errors of the export against the table, with a floor under the reference: a value
// below 2 % of its channel's mean (a dye's near-black channel, the table's noise floor) is
// judged against that 2 % instead, as a renderer's eye judges it (an absolute error of 0.02 of
// the channel's mean), so that the ratio of two tiny numbers does not stand for the file.
struct ErrorSet {
  std::vector<double> rel;
  void add(double got, double ref, double channel_mean) {
    rel.push_back(std::abs(got - ref) / std::max(ref, 0.02 * channel_mean));
  }
  double p95() {
    std::sort(rel.begin(), rel.end());
    return rel.empty() ? 0 : rel[rel.size() * 95 / 100];
  }
};

struct GrazingFigures {
  double p95 = 0;                           // relative error of f cos over directions to 85 deg
  double p95_beyond = 0, worst_beyond = 0;  // views at 85 .. 89.5 deg, lights to 89.5 deg
  double retro85 = 0;  // relative error of the back-scatter, view and light at 85 deg (channel 0)
  std::map<double, double> p95_at;  // per view angle (deg): p95 over lights to 85 deg
  std::map<double, double> albedo;  // relative error of the albedo per view angle (deg), worst
};

// A direction with cos theta uniform down to 'theta_max' and a uniform azimuth.
Vec3 random_direction(Rng& rng, double theta_max) {
  const double span = 1 - std::cos(theta_max);
  return spherical_direction(std::acos(1 - span * rng.uniform()), 2 * kPi * rng.uniform());
}

// The albedo towards 'v' per channel, int f cos d omega_light by the midpoint rule in
// (cos theta, phi), 64 x 128 points, of the export (got) and of the table (ref).
void albedo_pair(const TableReader& t, const RglEvaluator& e, const Vec3& v,
                 std::vector<double>& got, std::vector<double>& ref) {
  got.assign(static_cast<size_t>(t.channels()), 0.0);
  ref = got;
  for (int a = 0; a < 64; ++a)
    for (int b = 0; b < 128; ++b) {
      const Vec3 l = spherical_direction(std::acos((a + 0.5) / 64), 2 * kPi * (b + 0.5) / 128);
      const auto r = table_f_cos(t, v, l);
      for (int c = 0; c < t.channels(); ++c) {
        ref[static_cast<size_t>(c)] += r[static_cast<size_t>(c)];
        got[static_cast<size_t>(c)] += e.eval(v, l, c);
      }
    }
}

// Views and lights to 85 deg (cos theta uniform), views at fixed angles with lights to 85 deg,
// views beyond 85 deg, and the albedo towards views at 0 .. 89.5 deg, each against the table
// (table_f_cos). The error floor's channel means: the mean of f cos at normal view.
GrazingFigures grazing_figures(const TabulatedBsdfTable& table, const RglEvaluator& e) {
  GrazingFigures g;
  const TableReader t(table);
  const auto nc = static_cast<size_t>(t.channels());
  std::vector<double> got, normal;  // the albedo sums at normal view
  albedo_pair(t, e, {0, 0, 1}, got, normal);
  std::vector<double> mean = normal;
  for (double& m : mean) m /= 64 * 128;  // the mean of f cos over the grid's directions
  Rng rng(11);
  auto errors = [&](auto&& view, double light_max, int pairs, double* worst) {
    ErrorSet set;
    for (int n = 0; n < pairs; ++n) {
      const Vec3 v = view(), l = random_direction(rng, light_max);
      const auto r = table_f_cos(t, v, l);
      for (size_t c = 0; c < nc; ++c) {
        const double x = e.eval(v, l, static_cast<int>(c));
        set.add(x, r[c], mean[c]);
        if (worst && r[c] > 0.02 * mean[c]) *worst = std::max({*worst, x / r[c], r[c] / x});
      }
    }
    return set.p95();
  };
  const double d85 = deg_to_rad(85), d895 = deg_to_rad(89.5);
  g.p95 = errors([&] { return random_direction(rng, d85); }, d85, 2000, nullptr);
  for (double deg : {0.0, 20.0, 40.0, 60.0, 70.0, 75.0, 80.0, 85.0})
    g.p95_at[deg] =
        errors([&] { return spherical_direction(deg_to_rad(deg), 2 * kPi * rng.uniform()); }, d85,
               400, nullptr);
  const double c85 = std::cos(d85), c895 = std::cos(d895);
  g.p95_beyond = errors(
      [&] { return spherical_direction(std::acos(c895 + (c85 - c895) * rng.uniform()), 0.0); },
      d895, 2000, &g.worst_beyond);
  const Vec3 w85 = spherical_direction(d85, 0.3);
  g.retro85 = e.eval(w85, w85, 0) / table_f_cos(t, w85, w85)[0] - 1;
  std::vector<double> ref;
  for (double deg : {0.0, 40.0, 70.0, 80.0, 82.5, 85.0, 89.0, 89.5}) {
    albedo_pair(t, e, spherical_direction(deg_to_rad(deg), 0.3), got, ref);
    double worst = 0;
    for (size_t c = 0; c < nc; ++c) {
      if (!(ref[c] > 0.02 * normal[c])) continue;  // a near-black channel, as above
      const double r = got[c] / ref[c] - 1;
      if (std::abs(r) > std::abs(worst)) worst = r;
    }
    g.albedo[deg] = worst;
  }
  return g;
}

void print_figures(const std::string& name, const GrazingFigures& g) {
  std::cout << name << ": p95 to 85 deg " << 100 * g.p95 << " %; per view angle";
  for (const auto& [deg, p] : g.p95_at) std::cout << " " << deg << " deg " << 100 * p << " %";
  std::cout << "; views 85-89.5 deg: p95 " << 100 * g.p95_beyond << " %, worst factor "
            << g.worst_beyond << "; back-scatter at 85 deg " << 100 * g.retro85 << " %; albedo";
  for (const auto& [deg, r] : g.albedo) std::cout << " " << deg << " deg " << 100 * r << " %";
  std::cout << "\n";
}

TEST(RglBsdf, LambertianAndFabricHoldTo85Degrees) {
  // Against the table itself (table_f_cos): p95 of the relative error of f cos over views and
  // lights to 85 deg at most 5 %, the albedo per view angle to 85 deg within 2 %. Measured:
  // p95 0.8 % (Lambertian) and 1.4 % (fabric), albedo within 0.1 % to 89.5 deg (with 16
  // rotations, 21 incidences spaced as the paper spaces them and point values: 1.9 % and 3.4 %,
  // albedo within 0.6 %); the writer with the paper's NDF estimate alone, 17 incidences and
  // 32 x 32 samples gave p95 10 % and albedo -3 % at 80 deg, -16 % at 85 deg, -27 % at 89.5 deg.
  // Beyond 85 deg: printed, not asserted.
  for (const auto& [name, table] : {std::pair{std::string("lambert"), testing::lambert_rgb()},
                                    std::pair{std::string("fabric"), testing::fabric_rgb()}}) {
    const RglEvaluator e(export_and_read(table, name + ".bsdf"));
    const GrazingFigures g = grazing_figures(table, e);
    print_figures(name, g);
    EXPECT_LE(g.p95, 0.05) << name;
    for (const auto& [deg, r] : g.albedo) {
      if (deg > 85) continue;
      EXPECT_LE(std::abs(r), 0.02) << name << " " << deg << " deg";
    }
  }
}

TEST(RglBsdf, WovenClothHoldsTo85Degrees) {
  // The same bounds on a table with a baked fabric's features (exchange_tables.h, woven_rgb),
  // against the table's own interpolation averaged over rotations (table_f_cos), the file read
  // as Mitsuba 3's `measured` reads it (rgl_reader.h). Its export's errors grew with the view
  // angle as the baked red-cotton table's did (docs/exchange.md): p95 8.4 % (the baked table
  // 8.7 %), 11 % at 75 deg; albedo -1.5 % at 85 deg (the baked table -3.7 %) with 16 rotations,
  // 21 incidences spaced as the paper spaces them and point values. Measured now: p95 1.1 %, at
  // most 1.6 % per view angle, albedo within 0.4 % to 85 deg.
  const auto table = testing::woven_rgb();
  const RglEvaluator e(export_and_read(table, "woven.bsdf"));
  const GrazingFigures g = grazing_figures(table, e);
  print_figures("woven", g);
  EXPECT_LE(g.p95, 0.05);
  for (const auto& [deg, p] : g.p95_at)
    if (deg <= 85) EXPECT_LE(p, 0.05) << deg << " deg";
  for (const auto& [deg, r] : g.albedo)
    if (deg <= 85) EXPECT_LE(std::abs(r), 0.02) << deg << " deg";
}

// The in-plane mirror peak, beta = pi f of channel 1 (green), views every 0.5 degree within 10
// degrees of the mirror of 'deg': of the table averaged over 64 rotations (TableView) and of the
// file read back.
struct MirrorPeak {
  double table = 0, table_view = 0, file = 0, file_view = 0;
};
MirrorPeak mirror_peak(const TableView& view, const RglEvaluator& e, double deg) {
  MirrorPeak p;
  const Vec3 wi = spherical_direction(deg_to_rad(deg), 0);
  std::vector<double> f(3);
  for (double v = deg - 10; v <= deg + 10 + 1e-9; v += 0.5) {
    const Vec3 wo = spherical_direction(deg_to_rad(v), kPi);
    view.isotropic(wo, wi, f);
    if (kPi * f[1] > p.table) p.table = kPi * f[1], p.table_view = v;
    const double file = kPi * e.eval(wo, wi, 1) / wi.z;  // the file's f cos theta_light
    if (file > p.file) p.file = file, p.file_view = v;
  }
  return p;
}

TEST(RglBsdf, ASheenTablesPeakIsExported) {
  // The woven cloth with a sharp sheen beside its cells (gaussian_sheen: 3 degrees in the half
  // vector; f about 1 / sr above the rest at the mirror of 30 degrees). The export reads it
  // through TableView, with the sheen: the table's in-plane peak is 3.7, 5.4 and 7.9 times what
  // the cells alone give at 30, 45 and 60 degrees (measured: beta 3.09 against 0.83 at 30).
  // The file's 48 x 48 samples per incidence do not hold such a peak to the grazing bounds of
  // WovenClothHoldsTo85Degrees (docs/exchange.md, "A table with a sheen"): measured, the peak
  // +10.5 %, +0.8 %, +11.8 % at 30, 45, 60 degrees (the projection onto the grid rings about
  // it); the albedo within 1.7 % to 70 degrees (-2.4 % at 80, +10 % at 85); p95 over
  // directions to 85 degrees 8.3 %. Bounds: the peak within 15 %, the albedo within 2 % to 70.
  auto table = testing::woven_rgb();
  table.kind = "fabric";
  table.add_sheen(testing::gaussian_sheen(8, 3, 3.0, 3.0));
  auto cells_only = table;
  cells_only.sheen.reset();
  const TableView with(table, 64), without(cells_only, 64);
  const RglEvaluator e(export_and_read(table, "sheen.bsdf"));
  for (double deg : {30.0, 45.0, 60.0}) {
    const MirrorPeak p = mirror_peak(with, e, deg), plain = mirror_peak(without, e, deg);
    std::cout << deg << " deg: table peak " << p.table << " at " << p.table_view << " deg (cells "
              << "alone " << plain.table << "), file " << p.file << " at " << p.file_view
              << " deg: " << 100 * (p.file / p.table - 1) << " %\n";
    EXPECT_GT(p.table, 3 * plain.table) << deg;
    EXPECT_NEAR(p.file, p.table, 0.15 * p.table) << deg;
  }
  const TableReader reader(table);
  std::vector<double> got, ref;
  for (double deg : {0.0, 40.0, 70.0}) {
    albedo_pair(reader, e, spherical_direction(deg_to_rad(deg), 0.3), got, ref);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], ref[c], 0.02 * ref[c]) << deg << " deg " << c;
  }
}

// The same figures for any table file, printed (docs/exchange.md's figures for a baked fabric):
// WEFT_RGL_TABLE=TABLE.exr build/tests/weft_tests_exchange --gtest_filter='*TableFile*'.
TEST(RglBsdf, FiguresForATableFile) {
  const char* path = std::getenv("WEFT_RGL_TABLE");
  if (!path) GTEST_SKIP() << "set WEFT_RGL_TABLE=TABLE.exr to measure that table's export";
  const auto table = TabulatedBsdfTable::read_exr(path);
  const auto file = testing::fresh_test_dir() / "file.bsdf";
  export_table(table, file, {});
  std::cout << file << ": " << std::filesystem::file_size(file) << " bytes\n";
  const RglEvaluator e(testing::read_rgl(file));
  print_figures(path, grazing_figures(table, e));
  // The in-plane mirror peaks in the warp's plane (green), the table's own (read with its sheen)
  // and the file's.
  const TableView view(table, 64);
  for (double deg : {30.0, 45.0, 60.0}) {
    const MirrorPeak p = mirror_peak(view, e, deg);
    std::cout << "mirror peak at " << deg << " deg: table " << p.table << " at " << p.table_view
              << " deg, file " << p.file << " at " << p.file_view << " deg ("
              << 100 * (p.file / p.table - 1) << " %)\n";
  }
}

TEST(RglBsdf, BadExtensionNamesTheFileAndField) {
  const auto path = testing::fresh_test_dir() / "x.brdf";
  const std::string msg =
      testing::error_of([&] { export_table(testing::lambert_rgb(2), path, {}); });
  EXPECT_NE(msg.find("x.brdf"), std::string::npos) << msg;
  EXPECT_NE(msg.find("output"), std::string::npos) << msg;
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace weft
