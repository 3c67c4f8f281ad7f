// The RGL .bsdf export read back by an independent reader (rgl_reader.h) and evaluated the way
// Mitsuba 3's and pbrt-v4's `measured` BSDFs evaluate it.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <set>

#include "exchange_tables.h"
#include "rgl_reader.h"
#include "test_util.h"
#include "weft/core/frame.h"
#include "weft/core/rng.h"
#include "weft/exchange/export_table.h"

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
  // The interpolation error of the 48 x 48 sample grid and 21 incidence angles: measured median
  // 0.24 %, 95th percentile 1.3 % (the largest, 35 %, at grazing light and view).
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

// The export's target: the table's f cos theta_light averaged over the 16 rotations 2 pi k / 16
// of both directions about the normal (rgl_bsdf.h), from the table's own interpolation.
double table_f_cos(const TabulatedBsdfTable& t, const Vec3& v, const Vec3& l, int c) {
  std::vector<double> f(static_cast<size_t>(t.channels));
  double sum = 0;
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * kPi * k / 16, ca = std::cos(a), sa = std::sin(a);
    auto turn = [&](const Vec3& w) { return Vec3{ca * w.x - sa * w.y, sa * w.x + ca * w.y, w.z}; };
    t.interpolate(turn(v), turn(l), f);
    sum += f[static_cast<size_t>(c)];
  }
  return sum / 16 * l.z;
}

struct GrazingFigures {
  double p95 = 0;                           // relative error of f cos over directions to 85 deg
  double p95_beyond = 0, worst_beyond = 0;  // views at 85 .. 89.5 deg, lights to 89.5 deg
  double retro85 = 0;               // relative error of the back-scatter, view and light at 85 deg
  std::map<double, double> albedo;  // relative error of the albedo per view angle (deg)
};

// Views and lights to 85 deg (cos theta uniform), and the albedo towards views at 0 .. 89.5 deg,
// each against the table (table_f_cos, the same 64 x 128 rule).
GrazingFigures grazing_figures(const TabulatedBsdfTable& t, const RglEvaluator& e) {
  GrazingFigures g;
  Rng rng(11);
  std::vector<double> rel;
  const double span = 1 - std::cos(deg_to_rad(85));
  for (int n = 0; n < 2000; ++n) {
    const Vec3 v =
        spherical_direction(std::acos(1 - span * rng.uniform()), 2 * kPi * rng.uniform());
    const Vec3 l =
        spherical_direction(std::acos(1 - span * rng.uniform()), 2 * kPi * rng.uniform());
    for (int c = 0; c < 3; ++c)
      rel.push_back(std::abs(e.eval(v, l, c) / table_f_cos(t, v, l, c) - 1));
  }
  std::sort(rel.begin(), rel.end());
  g.p95 = rel[rel.size() * 95 / 100];
  rel.clear();
  const double c85 = std::cos(deg_to_rad(85)), c895 = std::cos(deg_to_rad(89.5));
  for (int n = 0; n < 2000; ++n) {
    const Vec3 v = spherical_direction(std::acos(c895 + (c85 - c895) * rng.uniform()), 0.0);
    const Vec3 l =
        spherical_direction(std::acos(1 - (1 - c895) * rng.uniform()), 2 * kPi * rng.uniform());
    for (int c = 0; c < 3; ++c) {
      const double ratio = e.eval(v, l, c) / table_f_cos(t, v, l, c);
      rel.push_back(std::abs(ratio - 1));
      g.worst_beyond = std::max({g.worst_beyond, ratio, 1 / ratio});
    }
  }
  std::sort(rel.begin(), rel.end());
  g.p95_beyond = rel[rel.size() * 95 / 100];
  const Vec3 w85 = spherical_direction(deg_to_rad(85), 0.3);
  g.retro85 = e.eval(w85, w85, 0) / table_f_cos(t, w85, w85, 0) - 1;
  for (double deg : {0.0, 40.0, 70.0, 80.0, 82.5, 85.0, 89.0, 89.5}) {
    const Vec3 v = spherical_direction(deg_to_rad(deg), 0.3);
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
      double ref = 0, got = 0;
      for (int a = 0; a < 64; ++a)
        for (int b = 0; b < 128; ++b) {
          const Vec3 l = spherical_direction(std::acos((a + 0.5) / 64), 2 * kPi * (b + 0.5) / 128);
          ref += table_f_cos(t, v, l, c);
          got += e.eval(v, l, c);
        }
      const double r = got / ref - 1;
      if (std::abs(r) > std::abs(worst)) worst = r;
    }
    g.albedo[deg] = worst;
  }
  return g;
}

void print_figures(const std::string& name, const GrazingFigures& g) {
  std::cout << name << ": p95 to 85 deg " << 100 * g.p95 << " %; views 85-89.5 deg: p95 "
            << 100 * g.p95_beyond << " %, worst factor " << g.worst_beyond
            << "; back-scatter at 85 deg " << 100 * g.retro85 << " %; albedo";
  for (const auto& [deg, r] : g.albedo) std::cout << " " << deg << " deg " << 100 * r << " %";
  std::cout << "\n";
}

TEST(RglBsdf, LambertianAndFabricHoldTo85Degrees) {
  // Against the table itself (table_f_cos): p95 of the relative error of f cos over views and
  // lights to 85 deg at most 5 %, the albedo per view angle to 85 deg within 2 %. Measured:
  // p95 1.9 % (Lambertian) and 3.7 % (fabric), albedo within 0.6 % to 89.5 deg; the writer with
  // the paper's NDF estimate alone, 17 incidences and 32 x 32 samples gave p95 10 % and albedo
  // -3 % at 80 deg, -16 % at 85 deg, -27 % at 89.5 deg. Beyond 85 deg: printed, not asserted.
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
