// Properties every material must have, checked on each registered name (built through the
// registry, so a newly registered material without a case here fails the coverage check).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "chi2.h"
#include "table_context.h"
#include "test_util.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"

using namespace weft;
using namespace weft::testing;
using json = nlohmann::json;

namespace {

struct Material {
  std::string name;
  Bsdf bsdf;
  bool transmits;  // f may be non-zero for wo, wi on opposite sides
};

std::vector<Material> all_materials() {
  const auto fiber = ClassicFiberBsdf::create(Rgb(0.6, 0.3, 0.2), {MicrofacetModel::kGgx, 0.3});
  const MaterialContext ctx = context_with_tables(TabulatedBsdfTable::from_function(
      8, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb f = wo.z * wi.z > 0 ? fiber.eval(wo, wi) : Rgb(0.05);
        v[0] = f.r, v[1] = f.g, v[2] = f.b;
      },
      4, 3));
  return {
      {"lambert", make_bsdf("lambert", {{"reflectance", 0.9}}, ctx), false},
      {"cook_torrance", make_bsdf("cook_torrance", {{"alpha", 0.2}}, ctx), false},
      {"classic_fiber", make_bsdf("classic_fiber", {{"reflectance", 1.0}}, ctx), false},
      {"fiber_table", make_bsdf("fiber_table", {{"file", "tables/fiber.exr"}}, ctx), true},
      {"fabric_table", make_bsdf("fabric_table", {{"file", "tables/fabric.exr"}}, ctx), true},
      // On an opaque backing (upholstery foam): reflection only.
      {"fabric_table",
       make_bsdf("fabric_table", {{"file", "tables/fabric.exr"}, {"backing_reflectance", 0.6}},
                 ctx),
       false},
      {"measured_nbrdf", make_bsdf("measured_nbrdf", {{"name", "merl-white-fabric"}}, ctx), false},
  };
}

const std::vector<Material>& materials() {
  static const std::vector<Material> m = all_materials();
  return m;
}

}  // namespace

TEST(EveryMaterial, IsCoveredHere) {
  std::vector<std::string> names;
  for (const auto& m : materials()) names.push_back(m.name);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());  // variants of one material
  EXPECT_EQ(names, material_names());
}

TEST(EveryMaterial, SampleAgreesWithEvalAndPdf) {
  Rng rng(1);
  for (const auto& m : materials()) {
    for (double theta : {0.05, 0.8, 1.55, 2.0, 3.0}) {
      const Vec3 wo = spherical_direction(theta, 1.1);
      for (int i = 0; i < 300; ++i) {
        const auto s = m.bsdf.sample(wo, {rng.uniform(), rng.uniform()}, rng.uniform());
        if (!s) continue;
        ASSERT_TRUE(is_finite(s->wi)) << m.name;
        EXPECT_NEAR(length(s->wi), 1.0, 1e-9) << m.name;
        const double pdf = m.bsdf.pdf(wo, s->wi);
        EXPECT_NEAR(s->pdf, pdf, 1e-9 * pdf) << m.name;
        const Rgb f = m.bsdf.eval(wo, s->wi);
        EXPECT_GE(std::min({f.r, f.g, f.b}), 0.0) << m.name;
        const Rgb expect = f * (std::abs(s->wi.z) / pdf);
        EXPECT_NEAR(s->weight.g, expect.g, 1e-9 * std::max(1.0, expect.g)) << m.name;
        if (!m.transmits) {
          EXPECT_GT(s->wi.z * wo.z, 0.0) << m.name;
        }
      }
    }
  }
}

TEST(EveryMaterial, PdfIntegratesToAtMostOneAndAlbedoToAtMostOne) {
  uint64_t seed = 5;
  for (const auto& m : materials()) {
    for (double theta : {0.3, 1.2, 2.6}) {
      const Vec3 wo = spherical_direction(theta, -0.4);
      double total = 0;
      for (double c : SphericalGrid{}.integrate(bsdf_pdf(m.bsdf, wo))) total += c;
      // Integration error of the grid for the tables' piecewise-constant pdf: ~1e-3.
      EXPECT_LE(total, 1.0 + 3e-3) << m.name << " theta " << theta;
      const auto a = estimate_albedo(m.bsdf, wo, 20000, seed++);
      const double worst = a.mean.max_component();
      // The tables' equator cells may exceed 1 by their discretization (see test_table_bsdf).
      EXPECT_LE(worst, 1.0 + 4 * a.standard_error.max_component() + 5e-3)
          << m.name << " theta " << theta;
    }
  }
}
