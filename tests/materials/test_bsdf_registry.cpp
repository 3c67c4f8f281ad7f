// make_bsdf: every material by name, and errors that name the file and field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "table_context.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdfs.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"

using namespace weft;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

// Materials as a scene's binding "materials.seat" in scene.json sees them, with a fiber and a
// fabric table in the test's folder (ctx.base_dir).
MaterialContext seat_context() {
  auto f = [](const Vec3&, const Vec3& wi, std::span<double> v) {
    v[0] = v[1] = v[2] = 0.1 + 0.1 * wi.z * wi.z;
  };
  MaterialContext ctx =
      weft::testing::context_with_tables(TabulatedBsdfTable::from_function(4, 3, f, 1));
  ctx.source_file = "scene.json";
  ctx.field_prefix = "materials.seat";
  return ctx;
}

std::string error_of(const std::string& type, const json& params, const MaterialContext& ctx) {
  return weft::testing::error_of([&] { make_bsdf(type, params, ctx); });
}

// The error must name the file and the full field path.
void expect_error(const std::string& type, const json& params, const MaterialContext& ctx,
                  const std::string& field, const std::string& also = "") {
  const std::string msg = error_of(type, params, ctx);
  ASSERT_FALSE(msg.empty()) << type << " accepted " << params.dump();
  EXPECT_NE(msg.find("scene.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'materials.seat." + field + "'"), std::string::npos) << msg;
  if (!also.empty()) {
    EXPECT_NE(msg.find(also), std::string::npos) << msg;
  }
}

}  // namespace

TEST(Registry, EveryNameConstructsFromValidParameters) {
  const MaterialContext ctx = seat_context();
  const std::pair<std::string, json> valid[] = {
      {"lambert", {{"reflectance", {0.8, 0.2, 0.1}}}},
      {"cook_torrance", {{"distribution", "ggx"}, {"alpha", 0.2}, {"ior", 1.557}, {"tint", 0.9}}},
      {"classic_fiber", {{"reflectance", 0.6}, {"distribution", "beckmann"}, {"roughness", 0.5}}},
      {"fiber_table", {{"file", "tables/fiber.exr"}, {"tint", {1, 0.5, 0.5}}, {"scale", 2}}},
      {"fabric_table", {{"file", "tables/fabric.exr"}}},
      {"measured_nbrdf", {{"name", "merl-red-fabric"}}},
  };
  std::vector<std::string> names;
  for (const auto& [type, params] : valid) {
    names.push_back(type);
    const Bsdf b = make_bsdf(type, params, ctx);
    const Vec3 wo{0.3, 0.1, std::sqrt(1 - 0.1)}, wi{-0.2, 0.3, std::sqrt(1 - 0.13)};
    EXPECT_GT(b.eval(wo, wi).max_component(), 0.0) << type;
    EXPECT_TRUE(b.sample(wo, {0.3, 0.6}, 0.4).has_value()) << type;
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, material_names()) << "every registered name is exercised here";
  // Defaults work too (an empty object).
  for (const std::string t : {"lambert", "cook_torrance", "classic_fiber"})
    EXPECT_NO_THROW(make_bsdf(t, json::object(), ctx)) << t;
}

TEST(Registry, ParametersReachTheMaterial) {
  const MaterialContext ctx = seat_context();
  const Bsdf ct = make_bsdf("cook_torrance", {{"distribution", "ggx"}, {"roughness", 0.5}}, ctx);
  const auto& c = std::get<CookTorranceBsdf>(ct.variant());
  EXPECT_EQ(c.distribution.model, MicrofacetModel::kGgx);
  EXPECT_DOUBLE_EQ(c.distribution.alpha, 0.25);  // alpha = roughness^2
  EXPECT_DOUBLE_EQ(c.ior, kCottonIor);
  const Bsdf t =
      make_bsdf("fiber_table", {{"file", "tables/fiber.exr"}, {"tint", 0.5}, {"scale", 2}}, ctx);
  EXPECT_EQ(std::get<TabulatedBsdf>(t.variant()).scale, Rgb(1.0));
  // Two materials on one file share one table.
  const Bsdf t2 = make_bsdf("fiber_table", {{"file", "./tables/../tables/fiber.exr"}}, ctx);
  EXPECT_EQ(std::get<TabulatedBsdf>(t.variant()).data.get(),
            std::get<TabulatedBsdf>(t2.variant()).data.get());
  // Interpolation: bilinear by default; "cell" reads the cell pair's own average, constant over
  // it (the table of seat_context varies with wi.z, so bilinear reads differ from it).
  EXPECT_EQ(std::get<TabulatedBsdf>(t2.variant()).lookup, TableLookup::bilinear);
  const Bsdf cell =
      make_bsdf("fiber_table", {{"file", "tables/fiber.exr"}, {"interpolation", "cell"}}, ctx);
  const auto& tc = std::get<TabulatedBsdf>(cell.variant());
  const auto& tb = std::get<TabulatedBsdf>(t2.variant());
  EXPECT_EQ(tc.lookup, TableLookup::cell);
  // Sampling follows what eval reads unless "sampling" says otherwise (tabulated_bsdf.h).
  EXPECT_EQ(tc.sampling, TableLookup::cell);
  EXPECT_EQ(std::get<TabulatedBsdf>(t2.variant()).sampling, TableLookup::bilinear);
  const Bsdf cell_old = make_bsdf(
      "fiber_table",
      {{"file", "tables/fiber.exr"}, {"interpolation", "cell"}, {"sampling", "bilinear"}}, ctx);
  EXPECT_EQ(std::get<TabulatedBsdf>(cell_old.variant()).lookup, TableLookup::cell);
  EXPECT_EQ(std::get<TabulatedBsdf>(cell_old.variant()).sampling, TableLookup::bilinear);
  const DirectionGrid& g = tc.data->grid;
  int differ = 0;
  for (int k = 0; k < 200; ++k) {
    Rng rng(3, uint64_t(k));
    auto dir = [&] {
      const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
      return Vec3{std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z};
    };
    const Vec3 wo = dir(), wi = dir();
    EXPECT_EQ(cell.eval(wo, wi), tc.data->lookup(g.bin_of(wi), g.bin_of(wo))) << k;
    differ += std::abs(tb.eval(wo, wi).r - cell.eval(wo, wi).r) > 1e-4;
  }
  EXPECT_GT(differ, 100);
}

TEST(Registry, UnknownTypeListsTheValidNames) {
  const MaterialContext ctx = seat_context();
  const std::string msg = error_of("velvet", json::object(), ctx);
  EXPECT_NE(msg.find("velvet"), std::string::npos) << msg;
  EXPECT_NE(msg.find("materials.seat.type"), std::string::npos) << msg;
  for (const auto& n : material_names())
    EXPECT_NE(msg.find(n), std::string::npos) << n << ": " << msg;
}

TEST(Registry, BadParametersAreNamed) {
  const MaterialContext ctx = seat_context();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_error("lambert", {{"reflectanse", 0.5}}, ctx, "reflectanse", "unknown key");
  expect_error("lambert", {{"reflectance", 1.5}}, ctx, "reflectance");
  expect_error("lambert", {{"reflectance", {0.5, 0.5}}}, ctx, "reflectance");
  expect_error("cook_torrance", {{"alpha", nan}}, ctx, "alpha");
  expect_error("cook_torrance", {{"alpha", 0.0}}, ctx, "alpha");
  expect_error("cook_torrance", {{"alpha", 2.0}}, ctx, "alpha");
  expect_error("cook_torrance", {{"alpha", "rough"}}, ctx, "alpha");
  expect_error("cook_torrance", {{"alpha", 0.2}, {"roughness", 0.4}}, ctx, "roughness");
  expect_error("cook_torrance", {{"distribution", "phong"}}, ctx, "distribution", "ggx");
  expect_error("cook_torrance", {{"ior", 0.5}}, ctx, "ior");
  expect_error("cook_torrance", {{"ior", nan}}, ctx, "ior");
  expect_error("cook_torrance", {{"tint", {0.5, nan, 0.5}}}, ctx, "tint[1]");
  expect_error("classic_fiber", {{"reflectance", -0.1}}, ctx, "reflectance");
  expect_error("classic_fiber", {{"tint", 0.5}}, ctx, "tint", "unknown key");
  expect_error("fiber_table", json::object(), ctx, "file", "required");
  expect_error("fiber_table", {{"file", 3}}, ctx, "file");
  expect_error("fiber_table", {{"file", "tables/none.exr"}}, ctx, "file", "none.exr");
  expect_error("fiber_table", {{"file", "tables/fabric.exr"}}, ctx, "file", "fabric table");
  expect_error("fabric_table", {{"file", "tables/fiber.exr"}}, ctx, "file", "fiber table");
  expect_error("fiber_table", {{"file", "tables/fiber.exr"}, {"scale", -1}}, ctx, "scale");
  expect_error("fiber_table", {{"file", "tables/fiber.exr"}, {"scale", nan}}, ctx, "scale");
  expect_error("fiber_table", {{"file", "tables/fiber.exr"}, {"interpolation", "nearest"}}, ctx,
               "interpolation", "bilinear, cell");
  expect_error("fiber_table", {{"file", "tables/fiber.exr"}, {"interpolation", 1}}, ctx,
               "interpolation");
  expect_error("fabric_table", {{"file", "tables/fabric.exr"}, {"interpolation", "cell"}}, ctx,
               "interpolation", "only to fiber_table");
  expect_error("fiber_table", {{"file", "tables/fiber.exr"}, {"sampling", "nearest"}}, ctx,
               "sampling", "bilinear, cell");
  expect_error("fabric_table", {{"file", "tables/fabric.exr"}, {"sampling", "cell"}}, ctx,
               "sampling", "only to fiber_table");
  expect_error("measured_nbrdf", {{"name", "blue-fabric"}}, ctx, "name", "merl-white-fabric");
  expect_error("measured_nbrdf", json::object(), ctx, "name", "exactly one");
  expect_error("measured_nbrdf", {{"file", "nbrdf.txt"}}, ctx, "file", "nbrdf.txt");
  expect_error("measured_nbrdf", {{"name", "merl-red-fabric"}, {"file", "x"}}, ctx, "name");
  // Parameters must be an object.
  const std::string msg = error_of("lambert", json::array({1, 2}), ctx);
  EXPECT_NE(msg.find("JSON object"), std::string::npos) << msg;
}

TEST(Registry, MeasuredByFileResolvesAgainstBaseDir) {
  const MaterialContext ctx = seat_context();
  fs::copy_file(find_measured_nbrdf("merl-white-fabric"), ctx.base_dir / "w.txt");
  const Bsdf by_file = make_bsdf("measured_nbrdf", {{"file", "w.txt"}}, ctx);
  const Bsdf by_name = make_bsdf("measured_nbrdf", {{"name", "merl-white-fabric"}}, ctx);
  const Vec3 wo{0, 0, 1}, wi{0.6, 0, 0.8};
  EXPECT_EQ(by_file.eval(wo, wi), by_name.eval(wo, wi));
}
