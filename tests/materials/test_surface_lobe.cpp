// The analytic surface lobe a table may name (materials/surface_lobe.h): its cell averages against
// an independent tabulation, its draws against its density, and its place in the table file.
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/surface_lobe.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

SurfaceLobe filament_lobe(int channels) {
  // Polyester filament's surface (fiber/presets/polyester-filament.json): GGX alpha 0.1, n 1.6;
  // a second index on the last channel so that channels differ.
  SurfaceLobe lobe{{MicrofacetModel::kGgx, 0.1}, std::vector<double>(channels, 1.6)};
  lobe.ior.back() = 1.45;
  return lobe;
}

TabulatedBsdfTable constant_table(int resolution, int channels, float value) {
  TabulatedBsdfTable t;
  t.resolution = resolution;
  t.channels = channels;
  t.kind = "fiber";
  t.values.assign(static_cast<size_t>(t.bins()) * t.bins() * channels, value);
  return t;
}

// The cell averages of f by the midpoint rule on fine grids of the equal-area chart: 12 x 12
// directions per wi bin and 32 x 32 per wo bin (under a degree apart at R 4, where the lobe is
// about 6 degrees wide), each weighted by its |cos theta|. It shares nothing with the quadrature
// under test but eval_upper. Only the rows of the wi bins in 'rows' (the rest stays 0).
std::vector<double> midpoint_cells(const SurfaceLobe& lobe, const DirectionGrid& grid,
                                   const std::vector<int>& rows) {
  const int ni = 12, no = 32, nc = lobe.channels();
  const size_t bins = static_cast<size_t>(grid.bins());
  std::vector<double> out(bins * bins * nc, 0.0);
  std::vector<double> f(nc);
  for (int row : rows) {
    const size_t i = static_cast<size_t>(row);
    for (size_t o = 0; o < bins; ++o) {
      if (!grid.upper(static_cast<int>(o))) continue;
      std::vector<double> sum(nc, 0.0);
      double wsum = 0;
      for (int a = 0; a < ni * ni; ++a) {
        const Vec3 wi = DirectionGrid::to_direction(
            grid.chart_point(static_cast<int>(i), (a % ni + 0.5) / ni, (a / ni + 0.5) / ni));
        for (int b = 0; b < no * no; ++b) {
          const Vec3 wo = DirectionGrid::to_direction(
              grid.chart_point(static_cast<int>(o), (b % no + 0.5) / no, (b / no + 0.5) / no));
          const double w = wi.z * wo.z;
          wsum += w;
          lobe.eval(wo, wi, f);
          for (int c = 0; c < nc; ++c) sum[c] += w * f[c];
        }
      }
      for (int c = 0; c < nc; ++c) out[(i * bins + o) * nc + c] = sum[c] / wsum;
    }
  }
  return out;
}

}  // namespace

// The quadrature (lobe draws booked into bins) against the midpoint rule, weighted like weft
// compare's rel_rms. Measured for GGX 0.1 against the quadrature itself at 32 x 32 wi directions
// and 64 x 64 draws: 0.11 % at R 4, 0.09 % at R 8 (0.72 % and 0.40 % with 8 x 8 wi directions).
TEST(SurfaceLobe, CellAveragesMatchTheMidpointRule) {
  for (const SurfaceLobe& lobe :
       {filament_lobe(3), SurfaceLobe{{MicrofacetModel::kBeckmann, 0.35}, {1.557, 1.557, 1.5}}}) {
    const DirectionGrid grid{4};
    const std::vector<double> quad = lobe.cell_averages(grid, 2);
    // The diagonal of the upper square: from the horizon's corner to the normal.
    const std::vector<int> rows = {0, 5, 10, 15};
    const std::vector<double> ref = midpoint_cells(lobe, grid, rows);
    const auto d = grid.cosine_weighted_areas();
    double num = 0, den = 0;
    for (int i : rows)
      for (int o = 0; o < grid.bins(); ++o)
        for (int c = 0; c < 3; ++c) {
          const size_t k = (static_cast<size_t>(i) * grid.bins() + o) * 3 + c;
          const double w = d[i] * d[o];
          num += w * (quad[k] - ref[k]) * (quad[k] - ref[k]);
          den += w * ref[k] * ref[k];
          if (!grid.upper(o)) EXPECT_EQ(quad[k], 0.0);
        }
    for (size_t k = 0; k < quad.size() / 2; ++k) EXPECT_EQ(quad[quad.size() / 2 + k], 0.0);
    std::printf("alpha %.2f: rel rms %.4f\n", lobe.distribution.alpha, std::sqrt(num / den));
    EXPECT_LT(std::sqrt(num / den), 0.01) << "alpha " << lobe.distribution.alpha;
    // Channels of another index differ by their Fresnel factor alone.
    EXPECT_NE(quad[3 * 5 + 2], quad[3 * 5 + 0]);
  }
}

// E[f cos_o / pdf] over the draws is the directional albedo, which a plain quadrature of f
// |cos_o| over the hemisphere gives too; and the draws' density integrates to at most 1.
TEST(SurfaceLobe, DrawsAndDensityAgreeWithTheLobe) {
  const SurfaceLobe lobe = filament_lobe(1);
  for (double theta_deg : {0.0, 30.0, 60.0, 80.0}) {
    const double t = theta_deg * kPi / 180;
    const Vec3 wi{std::sin(t), 0, std::cos(t)};
    Rng rng(11);
    double sampled = 0, pdf_mass = 0;
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
      double p = 0;
      const auto wo = lobe.sample(wi, {rng.uniform(), rng.uniform()}, &p);
      if (!wo) continue;
      EXPECT_NEAR(p, lobe.pdf(wi, *wo), 1e-9 * p);
      sampled += lobe.eval(*wo, wi, 0) * wo->z / p;
    }
    // Uniform directions over the hemisphere: f |cos_o| and pdf, each times 2 pi.
    double albedo = 0;
    for (int k = 0; k < n; ++k) {
      const double z = rng.uniform(), phi = 2 * kPi * rng.uniform(), s = std::sqrt(1 - z * z);
      const Vec3 wo{s * std::cos(phi), s * std::sin(phi), z};
      albedo += lobe.eval(wo, wi, 0) * z * 2 * kPi;
      pdf_mass += lobe.pdf(wi, wo) * 2 * kPi;
    }
    sampled /= n, albedo /= n, pdf_mass /= n;
    EXPECT_NEAR(sampled, albedo, 0.03 * albedo) << theta_deg;
    EXPECT_LT(pdf_mass, 1.03) << theta_deg;
    EXPECT_GT(pdf_mass, 0.8) << theta_deg;
  }
}

TEST(SurfaceLobe, AddedAndTakenOutGivesTheCellsBackToRounding) {
  TabulatedBsdfTable t = constant_table(4, 3, 0.125f);
  const TabulatedBsdfTable before = t;
  t.add_surface_lobe(filament_lobe(3), 2);
  ASSERT_TRUE(t.surface_lobe);
  EXPECT_NE(t.values, before.values);
  const TabulatedBsdfTable rest = t.without_surface_lobe("t.exr", 1);
  EXPECT_FALSE(rest.surface_lobe);
  for (size_t k = 0; k < rest.values.size(); ++k)
    EXPECT_NEAR(rest.values[k], 0.125f, 1e-6f * std::max(1.0f, t.values[k])) << k;
  // A second lobe, or a table whose cells hold less than its lobe, is refused.
  EXPECT_NE(error_of([&] { t.add_surface_lobe(filament_lobe(3)); }).find("already"),
            std::string::npos);
  TabulatedBsdfTable short_cells = constant_table(4, 3, 0.0f);
  short_cells.surface_lobe = filament_lobe(3);
  const std::string msg = error_of([&] { short_cells.without_surface_lobe("t.exr"); });
  EXPECT_NE(msg.find("t.exr"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must include the lobe"), std::string::npos) << msg;
}

TEST(SurfaceLobe, FileKeepsTheLobeAndOlderFilesLoadWithout) {
  const fs::path dir = fresh_test_dir();
  TabulatedBsdfTable t = constant_table(3, kNumBands, 0.5f);
  SurfaceLobe lobe{{MicrofacetModel::kBeckmann, 0.2}, std::vector<double>(kNumBands, 1.5)};
  lobe.ior[4] = 1.0 / 3 + 1.2;  // not a short decimal: the file keeps 17 digits
  t.add_surface_lobe(lobe, 1);
  t.write_exr(dir / "lobe.exr");
  const TabulatedBsdfTable back = TabulatedBsdfTable::read_exr(dir / "lobe.exr");
  ASSERT_TRUE(back.surface_lobe);
  EXPECT_EQ(back.surface_lobe->ior, lobe.ior);
  EXPECT_EQ(back.surface_lobe->distribution.alpha, 0.2);
  EXPECT_EQ(back.surface_lobe->distribution.model, MicrofacetModel::kBeckmann);
  EXPECT_EQ(back.values, t.values);
  EXPECT_TRUE(back.metadata.empty());  // the lobe's attributes are not metadata

  // A table without a lobe has none after the round trip.
  constant_table(3, 3, 0.5f).write_exr(dir / "plain.exr");
  EXPECT_FALSE(TabulatedBsdfTable::read_exr(dir / "plain.exr").surface_lobe);
}

TEST(SurfaceLobe, MalformedLobeAttributesNameTheAttribute) {
  using Attrs = std::map<std::string, std::string>;
  const Attrs good = filament_lobe(3).attributes();
  auto refusal = [&](const std::string& key, const std::string& value) {
    Attrs a = good;
    if (value.empty())
      a.erase(key);
    else
      a[key] = value;
    return error_of([&] { SurfaceLobe::from_attributes(a, 3, "t.exr"); });
  };
  EXPECT_NE(refusal("surface_lobe_alpha", "x").find("surface_lobe_alpha"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_alpha", "0").find("[0.001, 2]"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_ior", "1.5,1.5").find("one per channel"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_ior", "1.5,,1.5").find("not a number"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_ior", "1.5,1.5,9").find("outside [1, 4]"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_distribution", "phong").find("ggx"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe", "phong").find("cook-torrance"), std::string::npos);
  EXPECT_NE(refusal("surface_lobe_ior", "").find("is required"), std::string::npos);
  Attrs orphan = good;
  orphan.erase("surface_lobe");
  EXPECT_NE(error_of([&] {
              SurfaceLobe::from_attributes(orphan, 3, "t.exr");
            }).find("without \"surface_lobe\""),
            std::string::npos);
  EXPECT_FALSE(SurfaceLobe::from_attributes({{"spec_hash", "1"}}, 3, "t.exr"));
  // Metadata may not take the lobe's names.
  TabulatedBsdfTable t = constant_table(2, 3, 0.1f);
  t.metadata["surface_lobe_alpha"] = "0.1";
  EXPECT_NE(error_of([&] { t.validate("t.exr"); }).find("reserved"), std::string::npos);
}
