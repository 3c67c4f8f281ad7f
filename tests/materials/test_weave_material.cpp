// fabric_table with a weave (weave_modulation.h, bound_bsdf.h): its parameters, where a uv lies in
// the repeat, and the bound BSDF's eval, sample and pdf against the table's.
#include <gtest/gtest.h>

#include <cmath>

#include "rgb_table.h"
#include "table_context.h"
#include "test_util.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/materials/bound_bsdf.h"
#include "weft/materials/registry.h"
#include "weft/materials/weave_modulation.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

// A weave of 3 x 2 cells over 2 mm x 1 mm whose value depends on the cell, the coarse bins and
// the channel, with a mean over the cells of exactly 1 for every bin pair and channel.
WeaveTable varied_weave(int channels) {
  WeaveTable w;
  w.resolution = 2;
  w.channels = channels;
  w.positions_u = 3;
  w.positions_v = 2;
  w.repeat_u_m = 0.002;
  w.repeat_v_m = 0.001;
  const int n = w.bins();
  w.modulation.resize(static_cast<size_t>(w.positions()) * n * n * channels);
  // Per (bins, channel) the six cells hold 0.25, 0.5, 1, 1.25, 1.5, 1.5 in a rotating order:
  // their mean is 1 exactly (binary fractions).
  const float kValues[6] = {0.25f, 0.5f, 1.0f, 1.25f, 1.5f, 1.5f};
  for (int p = 0; p < 6; ++p)
    for (int i = 0; i < n; ++i)
      for (int o = 0; o < n; ++o)
        for (int c = 0; c < channels; ++c)
          w.modulation[w.index(p, i, o, c)] = kValues[(p + i + 2 * o + c) % 6];
  return w;
}

TabulatedBsdfTable lambert_like() {
  return rgb_table(4, [](const Vec3& wo, const Vec3& wi) {
    return Rgb(wo.z * wi.z > 0 ? 0.6 / kPi : 0.2 / kPi, 0.4 / kPi, 0.3 / kPi);
  });
}

Bsdf fabric(const MaterialContext& ctx, nlohmann::json params) {
  params["file"] = "tables/fabric.exr";
  return make_bsdf("fabric_table", params, ctx);
}

}  // namespace

TEST(WeaveMaterial, ReadsItsParamsAndLoadsTheWeave) {
  const MaterialContext ctx = context_with_tables(lambert_like());
  varied_weave(3).write_exr(ctx.base_dir / "weave.exr");
  const Bsdf b = fabric(ctx, {{"weave", "weave.exr"}, {"uv_metres", 0.01}});
  const auto& t = std::get<TabulatedBsdf>(b.variant());
  ASSERT_TRUE(t.weave);
  EXPECT_EQ(t.weave->level, WeaveLevel::automatic);  // the default with a weave
  EXPECT_EQ(t.weave->uv_metres, 0.01);
  EXPECT_EQ(t.weave->min_pixels, 4.0);
  EXPECT_EQ(t.weave->modulation->table().positions_u, 3);
  const Bsdf forced =
      fabric(ctx, {{"weave", "weave.exr"}, {"level", "weave"}, {"weave_min_pixels", 10}});
  EXPECT_EQ(std::get<TabulatedBsdf>(forced.variant()).weave->level, WeaveLevel::weave);
  EXPECT_EQ(std::get<TabulatedBsdf>(forced.variant()).weave->min_pixels, 10.0);
  // Without a weave nothing changes: no weave, the table as before.
  EXPECT_FALSE(std::get<TabulatedBsdf>(fabric(ctx, nlohmann::json::object()).variant()).weave);
}

TEST(WeaveMaterial, BadParamsNameTheField) {
  const MaterialContext ctx = context_with_tables(lambert_like());
  varied_weave(3).write_exr(ctx.base_dir / "weave.exr");
  auto error = [&](const std::string& type, nlohmann::json params) {
    return error_of([&] { make_bsdf(type, params, ctx); });
  };
  const std::string level =
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"level", "weave"}});
  EXPECT_NE(level.find("'level'"), std::string::npos) << level;
  EXPECT_NE(level.find("'weave'"), std::string::npos) << level;
  EXPECT_NE(
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"uv_metres", 2}}).find("'uv_metres'"),
      std::string::npos);
  EXPECT_NE(
      error("fiber_table", {{"file", "tables/fiber.exr"}, {"weave", "weave.exr"}}).find("'weave'"),
      std::string::npos);
  EXPECT_NE(error("fabric_table",
                  {{"file", "tables/fabric.exr"}, {"weave", "weave.exr"}, {"level", "fine"}})
                .find("'level'"),
            std::string::npos);
  EXPECT_NE(error("fabric_table",
                  {{"file", "tables/fabric.exr"}, {"weave", "weave.exr"}, {"uv_metres", 0}})
                .find("'uv_metres'"),
            std::string::npos);
  const std::string missing =
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"weave", "none.exr"}});
  EXPECT_NE(missing.find("'weave'"), std::string::npos) << missing;
  EXPECT_NE(missing.find("none.exr"), std::string::npos) << missing;
  // A weave belongs to the table it was baked with: a spectral weave on an RGB table is refused.
  varied_weave(kNumBands).write_exr(ctx.base_dir / "spectral.exr");
  const std::string channels =
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"weave", "spectral.exr"}});
  EXPECT_NE(channels.find("channels"), std::string::npos) << channels;
  // A weave records the table it was baked with (fabric_checksum); another table's is refused.
  WeaveTable other = varied_weave(3);
  other.metadata["fabric_checksum"] = "0123456789abcdef";
  other.write_exr(ctx.base_dir / "other.exr");
  const std::string foreign =
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"weave", "other.exr"}});
  EXPECT_NE(foreign.find("'weave'"), std::string::npos) << foreign;
  EXPECT_NE(foreign.find("0123456789abcdef"), std::string::npos) << foreign;
  WeaveTable own = varied_weave(3);
  own.metadata["fabric_checksum"] = lambert_like().checksum();
  own.write_exr(ctx.base_dir / "own.exr");
  EXPECT_NO_THROW(fabric(ctx, {{"weave", "own.exr"}}));
  // The fabric table named as a weave: its kind says what it is.
  const std::string kind =
      error("fabric_table", {{"file", "tables/fabric.exr"}, {"weave", "tables/fabric.exr"}});
  EXPECT_NE(kind.find("'kind'"), std::string::npos) << kind;
}

TEST(WeaveModulation, LocatesOnTheTorusAndBlendsNeighbours) {
  const WeaveModulation m(varied_weave(3));
  const double uv_m = 0.001;  // 1 mm per uv unit: the repeat is 2 x 1 uv units
  // Centre of cell (1, 1): weight 1 on it (pos = 1 * 3 + 1).
  const WeavePoint c = m.locate({1.0, 0.75}, uv_m);
  double on_cell = 0;
  for (int k = 0; k < 4; ++k)
    if (c.pos[k] == 4) on_cell += c.weight[k];
  EXPECT_NEAR(on_cell, 1.0, 1e-12);
  // Periodic: one repeat further, or a negative number of repeats, is the same point.
  for (const Vec2 shift : {Vec2{2, 0}, Vec2{0, 1}, Vec2{-6, -3}, Vec2{2000, 1000}}) {
    const WeavePoint s = m.locate({1.3 + shift.x, 0.1 + shift.y}, uv_m);
    const WeavePoint r = m.locate({1.3, 0.1}, uv_m);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(s.pos[k], r.pos[k]);
      EXPECT_NEAR(s.weight[k], r.weight[k], 1e-9);
    }
  }
  // The blend's mean over the repeat is the cells' mean, 1 (midpoint rule on a grid aligned with
  // the cells: exact for the piecewise bilinear blend), for any directions.
  Rng rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const Vec3 wo = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
    Vec3 wi = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
    if (trial % 2) wi.z = -wi.z;
    Rgb sum;
    const int nu = 60, nv = 40;
    for (int a = 0; a < nu; ++a)
      for (int b = 0; b < nv; ++b)
        sum += m.rgb(m.locate({(a + 0.5) * 2.0 / nu, (b + 0.5) * 1.0 / nv}, uv_m), wo, wi);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sum[ch] / (nu * nv), 1.0, 1e-9) << trial;
  }
}

TEST(BoundBsdf, IsTheTableTimesTheModulationWithTheTablesDensity) {
  const MaterialContext ctx = context_with_tables(lambert_like());
  varied_weave(3).write_exr(ctx.base_dir / "weave.exr");
  const Bsdf b = fabric(ctx, {{"weave", "weave.exr"}, {"uv_metres", 0.001}});
  const WeaveModulation& m = *std::get<TabulatedBsdf>(b.variant()).weave->modulation;
  const BoundBsdf plain{&b, nullptr, {}};
  const BoundBsdf bound{&b, &m, m.locate({0.4, 0.3}, 0.001)};
  Rng rng(9);
  for (int k = 0; k < 200; ++k) {
    const Vec3 wo = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
    const Vec2 u{rng.uniform(), rng.uniform()};
    const double u_lobe = rng.uniform();
    const auto s0 = b.sample(wo, u, u_lobe);
    const auto s1 = bound.sample(wo, u, u_lobe);
    const auto sp = plain.sample(wo, u, u_lobe);
    ASSERT_EQ(bool(s0), bool(s1));
    if (!s0) continue;
    EXPECT_EQ(s1->wi, s0->wi);  // sampled from the table as before
    EXPECT_EQ(s1->pdf, s0->pdf);
    EXPECT_EQ(sp->weight, s0->weight);  // unbound: the material itself
    const Rgb mod = m.rgb(bound.at, wo, s0->wi);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(s1->weight[c], s0->weight[c] * mod[c], 1e-12 * (1 + s0->weight[c]));
      EXPECT_NEAR(bound.eval(wo, s0->wi)[c], b.eval(wo, s0->wi)[c] * mod[c], 1e-12);
    }
    EXPECT_EQ(bound.pdf(wo, s0->wi), b.pdf(wo, s0->wi));
  }
}

TEST(BoundBsdf, SpectralWeaveModulatesEachBandAndReducesToRgbByBandMeans) {
  // A spectral fabric table and weave.
  const auto table = TabulatedBsdfTable::from_function(
      2, kNumBands,
      [](const Vec3&, const Vec3&, std::span<double> v) {
        for (int k = 0; k < kNumBands; ++k) v[k] = (0.2 + 0.01 * k) / kPi;
      },
      2, 1);
  const MaterialContext ctx = context_with_tables(table);
  varied_weave(kNumBands).write_exr(ctx.base_dir / "weave.exr");
  const Bsdf b = fabric(ctx, {{"weave", "weave.exr"}});
  EXPECT_EQ(spectral_obstacle(b), "");
  const WeaveModulation& m = *std::get<TabulatedBsdf>(b.variant()).weave->modulation;
  ASSERT_TRUE(m.has_bands());
  const BoundBsdf bound{&b, &m, m.locate({0.0013, 0.0004}, 1.0)};
  const Vec3 wo = normalize(Vec3{0.3, 0.1, 0.9}), wi = normalize(Vec3{-0.2, 0.4, 0.8});
  Spectrum f, fb, mb;
  eval_bands(b, wo, wi, f);
  eval_bands(bound, wo, wi, fb);
  m.bands(bound.at, wo, wi, mb);
  for (int k = 0; k < kNumBands; ++k) EXPECT_NEAR(fb[k], f[k] * mb[k], 1e-12);
  // RGB: per channel the band mean weighted by the positive sRGB weights (weave_modulation.h).
  const auto& w = srgb_band_weights_d65();
  const Rgb rgb = m.rgb(bound.at, wo, wi);
  for (int c = 0; c < 3; ++c) {
    double num = 0, den = 0;
    for (int k = 0; k < kNumBands; ++k)
      num += std::max(0.0, w[k][c]) * mb[k], den += std::max(0.0, w[k][c]);
    EXPECT_NEAR(rgb[c], num / den, 1e-6) << c;  // float storage of the reduced values
  }
}
