// fabric_table on an opaque Lambertian backing (backing_reflectance; tabulated_bsdf.h): the
// adding-doubling closed form f = f_R + rho_b / (1 - rho_b r_under) tau(wo) tau(wi) / pi, its
// energy, its limits, its reciprocity, its sampling and its parameter checks. The generic checks
// (sample agrees with eval and pdf, pdf and albedo <= 1) run on a backed table in
// test_bsdf_generic.cpp, the chi^2 test of its sampling in test_bsdf_chi2.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "chi2.h"
#include "rgb_table.h"
#include "table_context.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/registry.h"

using namespace weft;
using namespace weft::testing;
using json = nlohmann::json;

namespace {

TabulatedBsdfTable table_of(int resolution, const std::function<Rgb(const Vec3&, const Vec3&)>& f,
                            int spp = 4) {
  auto t = rgb_table(resolution, f, spp);
  t.kind = "fabric";
  return t;
}

// A lossless, reciprocal sheet with angular structure, written cell by cell: f[i][o] =
// (a + b X_i X_o) / pi between bins on the same side, (1 - a + c X_i X_o) / pi across, X_k the
// x of bin k's centre. X is odd under the grid's x mirror and the interpolation weights W are
// even, so the X terms integrate to 0 and every direction reflects a and transmits 1 - a
// (R + T = 1) from either side, while f varies with direction.
constexpr double kA = 0.3, kB = 0.2, kC = 0.25;
TabulatedBsdfTable lossless_table(int resolution) {
  TabulatedBsdfTable t;
  t.resolution = resolution;
  t.channels = 3;
  t.kind = "fabric";
  const DirectionGrid g = t.grid();
  const int n = g.bins();
  t.values.resize(size_t(n) * n * 3);
  for (int i = 0; i < n; ++i)
    for (int o = 0; o < n; ++o) {
      const double x = g.bin_center(i).x * g.bin_center(o).x;
      const double f = (g.upper(i) == g.upper(o) ? kA + kB * x : 1 - kA + kC * x) * kInvPi;
      for (int c = 0; c < 3; ++c) t.values[(size_t(i) * n + o) * 3 + c] = float(f);
    }
  return t;
}

// A lopsided, anisotropic, non-reciprocal, mostly transmitting sheet (like the summed fabric
// tables, which transmit 0.6-0.8 of red).
Rgb lumpy_backed(const Vec3& wo, const Vec3& wi) {
  const Vec3 m{-wo.x, -wo.y, wo.z};
  const double lobe = std::exp(-6 * length_squared(wi - m));
  const double same = 0.05 * (1 + 0.5 * wi.x + 0.3 * wo.y * wo.y) + 0.3 * lobe;
  const double across = 0.2 * (1 + 0.4 * wi.y * wi.y) * (1 + 0.2 * wo.x);
  const double f = wo.z * wi.z > 0 ? same : across;
  return Rgb(f, 0.6 * f, 0.3 * f);
}

TabulatedBsdf backed(const TabulatedBsdfTable& t, const Rgb& rho_b, const Rgb& scale = Rgb(1.0)) {
  TabulatedBsdf b{TabulatedBsdfData::prepare(t), scale};
  b.backing = TableBacking::make(*b.data, scale, rho_b);
  return b;
}

// int eval(wo, wi) |cos theta_i| dwi by the midpoint rule on a fine equal-area grid.
Rgb backed_albedo_by_quadrature(const Bsdf& b, const Vec3& wo) {
  Rgb sum;
  const OctahedralSquareGrid grid{1, 768};
  const int m = grid.n * grid.subdivisions;
  const double area = 4 * kPi / (double(m) * m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const Vec3 wi = equal_area_square_to_sphere({(i + 0.5) / m, (j + 0.5) / m});
      sum += b.eval(wo, wi) * (std::abs(wi.z) * area);
    }
  return sum;
}

// The table's reflection (wi above) and transmission (wi below) albedos at wo, by the midpoint
// rule on 768 x 768 equal-area points of the sphere.
struct SideAlbedos {
  Rgb refl, trans;
};
SideAlbedos albedos_by_side(const TabulatedBsdf& b, const Vec3& wo) {
  SideAlbedos s;
  const int m = 768;
  const double area = 4 * kPi / (double(m) * m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const Vec3 wi = equal_area_square_to_sphere({(i + 0.5) / m, (j + 0.5) / m});
      (wi.z > 0 ? s.refl : s.trans) += b.eval(wo, wi) * (std::abs(wi.z) * area);
    }
  return s;
}

const Vec3 kUpperWos[] = {spherical_direction(0.05, 0.2), spherical_direction(0.7, 2.0),
                          spherical_direction(1.2, -1.0), spherical_direction(1.5, 0.7)};

}  // namespace

TEST(TableBacking, HemisphereWeightsSumToPiPerHemisphereAndAreMirrorSymmetric) {
  for (int r : {1, 4, 8}) {
    const DirectionGrid g{r};
    const auto w = hemisphere_weights(g);
    double upper = 0, lower = 0;
    for (int k = 0; k < g.bins(); ++k) {
      ASSERT_GT(w[k], 0);
      (g.upper(k) ? upper : lower) += w[k];
      EXPECT_NEAR(w[k], w[g.mirrored_bin(k, 0)], 1e-12) << "R " << r << " bin " << k;
      EXPECT_NEAR(w[k], w[g.mirrored_bin(k, 2)], 1e-12) << "R " << r << " bin " << k;
    }
    EXPECT_NEAR(upper, kPi, 1e-12);
    EXPECT_NEAR(lower, kPi, 1e-12);
  }
}

TEST(TableBacking, AlbedosAreTheIntegralsOfTheInterpolatedTable) {
  // tau(wo) (other_side interpolated) and the reflection albedo (same_side) against quadrature
  // of the bare table's eval over each hemisphere. The 8 x 8-point weights are exact to the
  // quadrature's error, ~1e-4 of the albedo.
  const auto t = table_of(8, lumpy_backed);
  const TabulatedBsdf bare{TabulatedBsdfData::prepare(t), Rgb(1.0)};
  for (const Vec3& wo : kUpperWos) {
    const auto [refl, trans] = albedos_by_side(bare, wo);
    const Rgb same = bare.data->interpolate(bare.data->same_side, wo);
    const Rgb other = bare.data->interpolate(bare.data->other_side, wo);
    EXPECT_NEAR(same.r, refl.r, 1e-3 * refl.r) << wo;
    EXPECT_NEAR(other.r, trans.r, 1e-3 * trans.r) << wo;
    EXPECT_NEAR(other.b, trans.b, 1e-3 * trans.b) << wo;
  }
}

TEST(TableBacking, LosslessSheetOnANearlyWhiteBackingMatchesTheClosedFormAndStaysBelowOne) {
  // tau = 1 - a for every direction and r_under = a, so the backed albedo is
  //   a + rho_b (1 - a)^2 / (1 - rho_b a)   (-> 1 as rho_b -> 1),
  // the adding formula for a diffuse layer under a sheet.
  const auto t = lossless_table(8);
  for (double rho : {0.999, 0.5}) {
    const TabulatedBsdf b = backed(t, Rgb(rho));
    EXPECT_NEAR(b.data->underside_diffuse_albedo.g, kA, 1e-6);
    EXPECT_NEAR(b.data->diffuse_transmittance.g, 1 - kA, 1e-6);
    const double expect = kA + rho * sqr(1 - kA) / (1 - rho * kA);
    uint64_t seed = 17;
    for (const Vec3& wo : kUpperWos) {
      const Rgb q = backed_albedo_by_quadrature(b, wo);
      EXPECT_NEAR(q.g, expect, 2e-4) << "rho_b " << rho << " wo " << wo;
      EXPECT_LE(q.g, 1.0) << "rho_b " << rho << " wo " << wo;
      const auto mc = estimate_albedo(b, wo, 40000, seed++);
      EXPECT_NEAR(mc.mean.g, expect, 4 * mc.standard_error.g + 1e-4) << "rho_b " << rho;
      EXPECT_LE(mc.mean.g, 1.0 + 4 * mc.standard_error.g);
    }
  }
}

TEST(TableBacking, LumpySheetMatchesTheClosedFormByQuadrature) {
  // Not lossless, not reciprocal: albedo(wo) = R(wo) + rho_b / (1 - rho_b r_under) tau(wo) T_d,
  // with R, tau from the bare table's eval by quadrature, and r_under, T_d the diffuse albedos
  // the data holds (checked against quadrature in the test above, per direction).
  const auto t = table_of(8, lumpy_backed);
  const Rgb rho(0.6, 0.5, 0.4);
  const TabulatedBsdf b = backed(t, rho);
  const TabulatedBsdf bare{b.data, Rgb(1.0)};
  uint64_t seed = 99;
  for (const Vec3& wo : kUpperWos) {
    const Rgb q = backed_albedo_by_quadrature(b, wo);
    const auto [refl, trans] = albedos_by_side(bare, wo);
    for (int c = 0; c < 3; ++c) {
      const double rb = rho[c];
      const double expect = refl[c] + rb / (1 - rb * b.data->underside_diffuse_albedo[c]) *
                                          trans[c] * b.data->diffuse_transmittance[c];
      EXPECT_NEAR(q[c], expect, 2e-3 * expect) << "channel " << c << " wo " << wo;
    }
    const auto mc = estimate_albedo(b, wo, 40000, seed++);
    EXPECT_NEAR(mc.mean.r, q.r, 4 * mc.standard_error.r + 1e-3 * q.r) << wo;
  }
}

TEST(TableBacking, ZeroBackingIsTheReflectionPartAndTheBackIsBlack) {
  const auto t = table_of(8, lumpy_backed);
  const TabulatedBsdf zero = backed(t, Rgb(0.0));
  const TabulatedBsdf bare{zero.data, Rgb(1.0)};
  const TabulatedBsdf half = backed(t, Rgb(0.5));
  Rng rng(3);
  for (int n = 0; n < 500; ++n) {
    const Vec3 wo = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    const Vec3 wi = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    const bool above = wo.z > 0 && wi.z > 0;
    EXPECT_EQ(zero.eval(wo, wi), above ? bare.eval(wo, wi) : Rgb(0.0));
    EXPECT_EQ(zero.eval_backing(wo, wi), Rgb(0.0));
    if (!above) {
      EXPECT_EQ(half.eval(wo, wi), Rgb(0.0));  // no transmission, nothing from below
      EXPECT_EQ(half.pdf(wo, wi), 0.0);
    } else {
      EXPECT_GT(half.eval(wo, wi).r, bare.eval(wo, wi).r);
    }
    if (wo.z < 0) {
      EXPECT_FALSE(half.sample(wo, {rng.uniform(), rng.uniform()}, rng.uniform()));
    }
  }
}

TEST(TableBacking, BackingTermIsReciprocal) {
  // Even on a non-reciprocal table: one tau for both directions.
  const auto t = table_of(8, lumpy_backed);
  const TabulatedBsdf b = backed(t, Rgb(0.7, 0.6, 0.5), Rgb(0.9, 1.0, 0.8));
  Rng rng(11);
  for (int n = 0; n < 1000; ++n) {
    const Vec3 wo = spherical_direction(std::acos(rng.uniform()), 2 * kPi * rng.uniform());
    const Vec3 wi = spherical_direction(std::acos(rng.uniform()), 2 * kPi * rng.uniform());
    const Rgb a = b.eval_backing(wo, wi), c = b.eval_backing(wi, wo);
    ASSERT_GT(a.r, 0);
    EXPECT_NEAR(a.r, c.r, 1e-15 * a.r);
    EXPECT_NEAR(a.b, c.b, 1e-15 * a.b);
  }
}

TEST(TableBacking, SamplingMatchesEvalAndPdfOnAMostlyTransmittingSheet) {
  // The mixture's pdf integrates to 1 over the upper hemisphere (both parts are normalised
  // there): the table part is constant on fine cells (exact here), the cosine lobe is integrated
  // by the midpoint rule, whose error falls as h^2 (2.5e-4 at 8 points per cell side, 1.6e-5 at
  // 32). Then chi^2 of the samples against the pdf on the table's cells.
  const auto t = table_of(8, lumpy_backed);
  const TabulatedBsdf b = backed(t, Rgb(0.6));
  for (const Vec3& wo : kUpperWos) {
    double total = 0;
    for (double c :
         DirectionGridBins{8, 32}.integrate([&](const Vec3& wi) { return b.pdf(wo, wi); }))
      total += c;
    EXPECT_NEAR(total, 1.0, 3e-5) << wo;
  }
  const Bsdf bsdf = b;
  const DirectionGridBins grid{8, 8};
  uint64_t seed = 40;
  for (const Vec3& wo : kUpperWos) {
    const auto r = chi2_test(bsdf_sampler(bsdf, wo), bsdf_pdf(bsdf, wo), grid, 200000,
                             sidak_significance(0.01, 4), seed++);
    EXPECT_TRUE(r.passed) << wo << ": " << r.message;
  }
}

TEST(TableBacking, ParametersAreCheckedAndNamed) {
  const MaterialContext ctx = context_with_tables(table_of(4, lumpy_backed, 1));
  auto fails = [&](const std::string& type, const json& params, const std::string& what) {
    try {
      make_bsdf(type, params, ctx);
      ADD_FAILURE() << "accepted " << params.dump();
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("backing_reflectance"), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  const std::string file = "tables/fabric.exr";
  fails("fabric_table", {{"file", file}, {"backing_reflectance", std::nan("")}}, "");
  fails("fabric_table", {{"file", file}, {"backing_reflectance", -0.1}}, "");
  fails("fabric_table", {{"file", file}, {"backing_reflectance", 1.0}}, "below 1");
  fails("fabric_table", {{"file", file}, {"backing_reflectance", {0.5, 1.0, 0.2}}}, "below 1");
  fails("fabric_table", {{"file", file}, {"backing_reflectance", "foam"}}, "");
  fails("fiber_table", {{"file", "tables/fiber.exr"}, {"backing_reflectance", 0.5}},
        "only to fabric_table");
  // A scale that makes the underside reflect more than it receives: the series diverges.
  fails("fabric_table", {{"file", file}, {"backing_reflectance", 0.99}, {"scale", 10}},
        "all the light");
  // Accepted, and absent means no backing (the bare table, transmission included).
  const Bsdf ok = make_bsdf("fabric_table", {{"file", file}, {"backing_reflectance", 0.6}}, ctx);
  ASSERT_TRUE(std::get<TabulatedBsdf>(ok.variant()).backing);
  EXPECT_EQ(std::get<TabulatedBsdf>(ok.variant()).backing->reflectance, Rgb(0.6));
  const Bsdf bare = make_bsdf("fabric_table", {{"file", file}}, ctx);
  EXPECT_FALSE(std::get<TabulatedBsdf>(bare.variant()).backing);
}
