// Chi^2 goodness-of-fit of every material's sample() against its pdf() (Mitsuba 3 chi2.py
// procedure, see chi2.h), with one Sidak-corrected significance of 0.01 across all tests below.
#include <gtest/gtest.h>

#include <cmath>

#include "chi2.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/measured_nbrdf.h"
#include "weft/materials/tabulated_bsdf.h"

using namespace weft;
using namespace weft::testing;

namespace {

constexpr int kSamples = 300000;

struct CtCase {
  MicrofacetModel model;
  double alpha, theta_o_deg;
};
const CtCase kCookTorranceCases[] = {
    {MicrofacetModel::kBeckmann, 0.1, 0},
    {MicrofacetModel::kBeckmann, 0.1, 40},
    {MicrofacetModel::kBeckmann, 0.1, 70},
    {MicrofacetModel::kBeckmann, 0.1, 85},
    {MicrofacetModel::kBeckmann, 0.3, 0},
    {MicrofacetModel::kBeckmann, 0.3, 40},
    {MicrofacetModel::kBeckmann, 0.3, 70},
    {MicrofacetModel::kBeckmann, 0.3, 85},
    {MicrofacetModel::kBeckmann, 0.8, 0},
    {MicrofacetModel::kBeckmann, 0.8, 40},
    {MicrofacetModel::kBeckmann, 0.8, 70},
    {MicrofacetModel::kBeckmann, 0.8, 85},
    {MicrofacetModel::kGgx, 0.1, 0},
    {MicrofacetModel::kGgx, 0.1, 40},
    {MicrofacetModel::kGgx, 0.1, 70},
    {MicrofacetModel::kGgx, 0.1, 85},
    {MicrofacetModel::kGgx, 0.3, 0},
    {MicrofacetModel::kGgx, 0.3, 40},
    {MicrofacetModel::kGgx, 0.3, 70},
    {MicrofacetModel::kGgx, 0.3, 85},
    {MicrofacetModel::kGgx, 0.8, 0},
    {MicrofacetModel::kGgx, 0.8, 40},
    {MicrofacetModel::kGgx, 0.8, 70},
    {MicrofacetModel::kGgx, 0.8, 85},
    // The back side (theta_o > 90 deg) mirrors the front.
    {MicrofacetModel::kBeckmann, 0.3, 130},
    {MicrofacetModel::kGgx, 0.3, 130},
};
const double kLambertAngles[] = {0, 45, 85, 120};
struct FiberCase {
  MicrofacetModel model;
  double alpha, theta_o_deg;
};
const FiberCase kClassicFiberCases[] = {{MicrofacetModel::kBeckmann, 0.3, 10},
                                        {MicrofacetModel::kBeckmann, 0.3, 60},
                                        {MicrofacetModel::kBeckmann, 0.3, 85},
                                        {MicrofacetModel::kGgx, 0.1, 40},
                                        {MicrofacetModel::kGgx, 0.3, 150}};
// wo for the table tests: front, grazing, and from behind (tables cover the full sphere).
const Vec3 kTableWo[] = {spherical_direction(deg_to_rad(30), 0.4),
                         spherical_direction(deg_to_rad(80), 2.0),
                         spherical_direction(deg_to_rad(125), -1.0)};
const double kMeasuredAngles[] = {20, 70, 45};

constexpr int kChi2Tests =
    1 /* self-test acceptance */ + std::size(kLambertAngles) + std::size(kCookTorranceCases) +
    std::size(kClassicFiberCases) + 3 * std::size(kTableWo) + 2 /* backed table, wo above */ +
    std::size(kTableWo) /* table with a sheen */ + std::size(kMeasuredAngles);
const double kSignificance = sidak_significance(0.01, kChi2Tests);

void expect_chi2(const Bsdf& bsdf, const Vec3& wo, uint64_t seed, const std::string& what) {
  const auto r = chi2_test(bsdf_sampler(bsdf, wo), bsdf_pdf(bsdf, wo), SphericalGrid{}, kSamples,
                           kSignificance, seed);
  EXPECT_TRUE(r.passed) << what << ": " << r.message;
}

// A fiber-like table with reflection and transmission (light from behind), and an anisotropic
// fabric-like one, both at R = 8.
TabulatedBsdf fiber_like_table() {
  const auto fiber = ClassicFiberBsdf::create(Rgb(0.7, 0.3, 0.2), {MicrofacetModel::kGgx, 0.3});
  auto table = TabulatedBsdfTable::from_function(
      8, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        Rgb f = fiber.eval(wo, wi);
        if (wo.z * wi.z < 0) f = Rgb(0.1, 0.05, 0.02);  // diffuse transmission
        v[0] = f.r, v[1] = f.g, v[2] = f.b;
      },
      4, 7);
  return TabulatedBsdf{TabulatedBsdfData::prepare(table), Rgb(1.0)};
}
TabulatedBsdf fabric_like_table(std::optional<Rgb> backing = std::nullopt) {
  auto table = TabulatedBsdfTable::from_function(
      8, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        // Anisotropic: a lobe around the mirror direction stretched along x (the warp).
        const Vec3 m{-wo.x, -wo.y, wo.z};
        const double lobe = std::exp(-4 * sqr(wi.y - m.y) - 0.5 * sqr(wi.x - m.x));
        const double f = (wo.z * wi.z > 0 ? 0.15 : 0.02) + 0.4 * lobe;
        v[0] = f, v[1] = 0.8 * f, v[2] = 0.5 * f;
      },
      4, 11);
  table.kind = "fabric";
  TabulatedBsdf b{TabulatedBsdfData::prepare(table), Rgb(1.0)};
  if (backing) b.backing = TableBacking::make(*b.data, b.scale, *backing);
  return b;
}

// The same cells with a sheen over half vectors (half_vector_lobe.h) added: R_h 16, a window of
// 8 x 8 bins (each about 9 degrees), Q drawn per light bin and window bin; light bins at
// light_resolution (0: the table's R 8).
TabulatedBsdfTable fabric_table_with_sheen(int light_resolution = 0) {
  auto table = TabulatedBsdfTable::from_function(
      8, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const double f = wo.z * wi.z > 0 ? 0.15 : 0.02;
        v[0] = f, v[1] = 0.8 * f, v[2] = 0.5 * f;
      },
      1, 11);
  table.kind = "fabric";
  HalfVectorLobe sheen = HalfVectorLobe::zeros(8, 16, 8, 3, light_resolution);
  Rng rng(12, 0, 0);
  for (float& v : sheen.values) v = static_cast<float>(0.5 * rng.uniform());
  table.add_sheen(std::move(sheen));
  return table;
}

}  // namespace

TEST(Chi2Helper, SurvivalFunctionMatchesReferenceValues) {
  // chi^2 critical values at upper-tail probability 0.05 (NIST/SEMATECH e-Handbook of Statistical
  // Methods, table 1.3.6.7.4): dof 1 -> 3.841, dof 10 -> 18.307, dof 100 -> 124.342.
  EXPECT_NEAR(chi2_survival(3.841, 1), 0.05, 2e-5);
  EXPECT_NEAR(chi2_survival(18.307, 10), 0.05, 2e-5);
  EXPECT_NEAR(chi2_survival(124.342, 100), 0.05, 2e-5);
  // Analytic: for dof 2 the survival function is exp(-x/2).
  EXPECT_NEAR(chi2_survival(3.0, 2), std::exp(-1.5), 1e-12);
  EXPECT_NEAR(sidak_significance(0.01, 1), 0.01, 1e-15);
}

TEST(Chi2Helper, AcceptsACorrectSamplerAndRejectsAWrongPdf) {
  const Bsdf lambert = LambertBsdf{Rgb(0.5)};
  const Vec3 wo = direction(deg_to_rad(30));
  const auto ok = chi2_test(bsdf_sampler(lambert, wo), bsdf_pdf(lambert, wo), SphericalGrid{},
                            kSamples, kSignificance, 1);
  EXPECT_TRUE(ok.passed) << ok.message;
  // Cosine-distributed samples tested against a uniform-hemisphere pdf must fail.
  const auto bad = chi2_test(
      bsdf_sampler(lambert, wo), [](const Vec3& w) { return w.z > 0 ? 0.5 * kInvPi : 0.0; },
      SphericalGrid{}, kSamples, kSignificance, 2);
  EXPECT_FALSE(bad.passed) << bad.message;
  // So must a pdf of the right shape on the wrong side.
  const auto flipped = chi2_test(
      bsdf_sampler(lambert, wo), [](const Vec3& w) { return w.z < 0 ? -w.z * kInvPi : 0.0; },
      SphericalGrid{}, 1000, kSignificance, 3);
  EXPECT_FALSE(flipped.passed) << flipped.message;
}

TEST(Chi2, Lambert) {
  const Bsdf b = LambertBsdf{Rgb(0.6)};
  uint64_t seed = 100;
  for (double t : kLambertAngles) expect_chi2(b, direction(deg_to_rad(t)), seed++, "lambert");
}

TEST(Chi2, CookTorrance) {
  uint64_t seed = 200;
  for (const auto& c : kCookTorranceCases) {
    const Bsdf b = CookTorranceBsdf{{c.model, c.alpha}, 1.557, Rgb(1.0)};
    expect_chi2(b, direction(deg_to_rad(c.theta_o_deg)), seed++,
                std::string(microfacet_model_name(c.model)) + " alpha " + std::to_string(c.alpha) +
                    " theta_o " + std::to_string(c.theta_o_deg));
  }
}

TEST(Chi2, ClassicFiber) {
  uint64_t seed = 300;
  for (const auto& c : kClassicFiberCases) {
    const Bsdf b = ClassicFiberBsdf::create(Rgb(0.8, 0.2, 0.1), {c.model, c.alpha});
    expect_chi2(b, direction(deg_to_rad(c.theta_o_deg)), seed++,
                "classic_fiber theta_o " + std::to_string(c.theta_o_deg));
  }
}

TEST(Chi2, FiberAndFabricTables) {
  // Histogram on the tables' own cells (R = 8, see chi2.h): the pdf is constant on each.
  const DirectionGridBins grid{8, 4};
  uint64_t seed = 400;
  // The fiber table also read and sampled by cell (fiber_table "interpolation": "cell").
  TabulatedBsdf by_cell = fiber_like_table();
  by_cell.lookup = by_cell.sampling = TableLookup::cell;
  for (const Bsdf& b : {Bsdf(fiber_like_table()), Bsdf(fabric_like_table()), Bsdf(by_cell)}) {
    for (const Vec3& wo : kTableWo) {
      const auto r =
          chi2_test(bsdf_sampler(b, wo), bsdf_pdf(b, wo), grid, kSamples, kSignificance, seed++);
      EXPECT_TRUE(r.passed) << "table, wo " << wo << ": " << r.message;
    }
  }
  // On a backing: the table's reflection part or a cosine lobe, by albedo (wo above only; from
  // below a backed cloth is black and samples nothing).
  const Bsdf backed = fabric_like_table(Rgb(0.6));
  for (const Vec3& wo : {kTableWo[0], kTableWo[1]}) {
    EXPECT_FALSE(backed.sample(kTableWo[2], {0.3, 0.6}, 0.5));
    const auto r = chi2_test(bsdf_sampler(backed, wo), bsdf_pdf(backed, wo), grid, kSamples,
                             kSignificance, seed++);
    EXPECT_TRUE(r.passed) << "backed table, wo " << wo << ": " << r.message;
  }
}

// A table with a sheen: the cells' distribution or the sheen's own window draws (the pdf then
// changes at the window bins' edges: a histogram of R 16 cells, each integrated on 16 x 16
// points).
// Light bins of the sheen twice as fine as the table's (R_l 16): its draws per wo bin of R_l.
TEST(Chi2, FabricTableWithASheen) {
  uint64_t seed = 450;
  for (int light_resolution : {8, 16}) {
    const TabulatedBsdfTable table = fabric_table_with_sheen(light_resolution);
    const TabulatedBsdf t{TabulatedBsdfData::prepare(table), Rgb(1.0)};
    ASSERT_TRUE(t.data->sheen_rgb);
    const Bsdf b(t);
    for (const Vec3& wo : kTableWo) {
      const auto r = chi2_test(bsdf_sampler(b, wo), bsdf_pdf(b, wo), DirectionGridBins{16, 16},
                               kSamples, kSignificance, seed++);
      EXPECT_TRUE(r.passed) << "table with a sheen, R_l " << light_resolution << ", wo " << wo
                            << ": " << r.message;
    }
  }
}

TEST(Chi2, MeasuredNbrdf) {
  uint64_t seed = 500;
  int i = 0;
  for (double t : kMeasuredAngles) {
    const std::string name = i++ < 2 ? "merl-red-fabric" : "merl-white-fabric";
    const Bsdf b = MeasuredNbrdfBsdf{
        std::make_shared<const NbrdfNetwork>(NbrdfNetwork::load(find_measured_nbrdf(name)))};
    expect_chi2(b, direction(deg_to_rad(t)), seed++, name);
  }
}
