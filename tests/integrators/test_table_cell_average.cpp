// Every table stores one quantity, the cosine-weighted cell average (materials/bsdf_table.h). The
// same analytic BSDF tabulated the two ways the project makes tables - stratified sampling per
// cell pair (from_function, `weft table bake`) and a Monte Carlo estimator that gathers sums of
// f |cos_i| |cos_o| per cell pair and divides by D_i D_o (averages_from_weighted_sums, the fiber
// baker's normalization) - must agree cell by cell and render the same radiance coefficients.
// A plain solid-angle average of the same samples must NOT agree, so the test can tell them apart.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/integrators/gonio.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/cook_torrance.h"
#include "weft/scenes/description.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {

constexpr int kR = 4;  // coarse bins: the weighting inside a cell matters most

// A rough conductor-like lobe that varies strongly inside the coarse bins.
const CookTorranceBsdf kLobe{{MicrofacetModel::kGgx, 0.25}, 1.5, Rgb(1.0)};

double f_of(const Vec3& wo, const Vec3& wi) {
  return kLobe.eval(wo, wi).r;
}

struct MonteCarloTable {
  std::vector<double> average, std_error, plain;  // [wi bin][wo bin]
};

// The baker's estimator: N direction pairs uniform over sphere x sphere, each adding
// f |cos_i| |cos_o| (4 pi)^2 / N to its cell pair's sum; then the cell averages.
MonteCarloTable monte_carlo_table(uint64_t n) {
  const DirectionGrid grid{kR};
  const size_t cells = static_cast<size_t>(grid.bins());
  std::vector<double> sum(cells * cells, 0.0), sum2(cells * cells, 0.0), plain(cells * cells, 0.0);
  std::vector<double> count(cells * cells, 0.0);
  const double scale = 16 * kPi * kPi / static_cast<double>(n);
  Rng rng(11);
  for (uint64_t k = 0; k < n; ++k) {
    const Vec3 wi = DirectionGrid::to_direction({rng.uniform(), rng.uniform()});
    const Vec3 wo = DirectionGrid::to_direction({rng.uniform(), rng.uniform()});
    const size_t c = static_cast<size_t>(grid.bin_of(wi)) * cells + grid.bin_of(wo);
    const double f = f_of(wo, wi);
    const double x = f * std::abs(wi.z) * std::abs(wo.z) * scale;
    sum[c] += x;
    sum2[c] += x * x;
    plain[c] += f;
    count[c] += 1;
  }
  MonteCarloTable t;
  t.average = TabulatedBsdfTable::averages_from_weighted_sums(kR, sum);
  std::vector<double> se_sum(cells * cells);
  for (size_t c = 0; c < sum.size(); ++c) {
    const double m = sum[c] / static_cast<double>(n);  // mean contribution per sample
    const double var = std::max(0.0, sum2[c] / static_cast<double>(n) - m * m);
    se_sum[c] = std::sqrt(var * static_cast<double>(n));
    t.plain.push_back(count[c] > 0 ? plain[c] / count[c] : 0.0);
  }
  t.std_error = TabulatedBsdfTable::averages_from_weighted_sums(kR, se_sum);
  return t;
}

// from_function's estimate, averaged over independent seeds, with its standard error per cell
// (its stratified ratio estimator is far from exact in cells where the cosine weights vary most).
struct StratifiedTable {
  TabulatedBsdfTable table;  // the mean over seeds
  std::vector<double> std_error;
};
StratifiedTable stratified_table() {
  constexpr int kSeeds = 8;
  std::vector<double> s, s2;
  StratifiedTable out;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const auto t = TabulatedBsdfTable::from_function(
        kR, 3,
        [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
          v[0] = v[1] = v[2] = f_of(wo, wi);
        },
        512, 100 + seed);
    if (s.empty()) s.assign(t.values.size(), 0.0), s2.assign(t.values.size(), 0.0), out.table = t;
    for (size_t k = 0; k < s.size(); ++k)
      s[k] += t.values[k], s2[k] += double(t.values[k]) * t.values[k];
  }
  out.table.kind = "fabric";
  for (size_t k = 0; k < s.size(); ++k) {
    const double m = s[k] / kSeeds;
    out.table.values[k] = static_cast<float>(m);
    out.std_error.push_back(std::sqrt(std::max(0.0, s2[k] / kSeeds - m * m) / (kSeeds - 1)));
  }
  return out;
}

fs::path temp_file(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "weft-table-cell-average";
  fs::create_directories(dir);
  return dir / name;
}

}  // namespace

TEST(TableCellAverage, StratifiedAndMonteCarloTablesHoldTheSameQuantity) {
  const StratifiedTable st = stratified_table();
  const TabulatedBsdfTable& a = st.table;
  const MonteCarloTable b = monte_carlo_table(uint64_t{1} << 23);
  const size_t cells = static_cast<size_t>(DirectionGrid{kR}.bins());
  int compared = 0, outliers = 0, plain_differs = 0;
  for (size_t i = 0; i < cells; ++i)
    for (size_t o = 0; o < cells; ++o) {
      const size_t c = i * cells + o;
      const double va = a.at(static_cast<int>(i), static_cast<int>(o), 0);
      if (!(b.std_error[c] > 0)) {
        EXPECT_EQ(va, 0.0) << i << " " << o;  // cells the lobe never reaches
        continue;
      }
      ++compared;
      // Both estimates within their combined standard error (1e-6: float storage).
      const double se = std::hypot(st.std_error[c * 3], b.std_error[c]);
      if (std::abs(va - b.average[c]) > 4.5 * se + 1e-6 * va) ++outliers;
      if (std::abs(b.plain[c] - b.average[c]) > 10 * b.std_error[c]) ++plain_differs;
    }
  ASSERT_GT(compared, 40);
  EXPECT_EQ(outliers, 0);
  // The plain solid-angle average is a different quantity in many cells (grazing ones above all).
  EXPECT_GT(plain_differs, compared / 10);
}

TEST(TableCellAverage, BothTablesRenderTheSameRadianceCoefficients) {
  const StratifiedTable st = stratified_table();
  const TabulatedBsdfTable& a = st.table;
  const MonteCarloTable mc = monte_carlo_table(uint64_t{1} << 23);
  TabulatedBsdfTable b = a;
  double max_rel_se = 0;
  for (size_t c = 0; c < mc.average.size(); ++c) {
    for (int ch = 0; ch < 3; ++ch) b.values[c * 3 + ch] = static_cast<float>(mc.average[c]);
    if (mc.average[c] > 1e-3)
      max_rel_se =
          std::max(max_rel_se, std::hypot(mc.std_error[c], st.std_error[c * 3]) / mc.average[c]);
  }
  const fs::path fa = temp_file("stratified.exr"), fb = temp_file("monte-carlo.exr");
  a.write_exr(fa);
  b.write_exr(fb);
  const fs::path examples = fs::path(WEFT_SOURCE_DIR) / "scenes/examples";
  GonioSettings g;
  g.sample = "plane";
  g.light_zenith_deg = 60;
  g.view_zenith_deg = {-60, -30, 0, 30, 60};
  g.width = g.height = 8;
  g.spp = 1;
  g.white_check = false;
  auto sweep = [&](const fs::path& table) {
    SceneDescription d = load_scene_description(examples / "lambert-plane.json");
    d.materials["plane"].type = "fabric_table";
    d.materials["plane"].params = {{"file", table.string()}};
    return run_gonio(d, g);
  };
  const GonioResult ra = sweep(fa), rb = sweep(fb);
  ASSERT_EQ(ra.rows.size(), rb.rows.size());
  for (size_t k = 0; k < ra.rows.size(); ++k) {
    const double beta_a = ra.rows[k].beta.r, beta_b = rb.rows[k].beta.r;
    ASSERT_GT(beta_a, 0) << ra.rows[k].view_zenith_deg;
    // A lookup blends 16 cells, each within its Monte Carlo error of the other table.
    EXPECT_NEAR(beta_b / beta_a, 1.0, 4.5 * max_rel_se + 1e-3) << ra.rows[k].view_zenith_deg;
  }
}
