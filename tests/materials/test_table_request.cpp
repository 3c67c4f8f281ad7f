// weft table's request, plan and run (materials/table_request.h): the plan refuses a bad material
// before any work, and the run tabulates the material it names.
#include <gtest/gtest.h>

#include "test_util.h"
#include "weft/materials/table_request.h"

using namespace weft;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

TEST(TableRequest, PlanNamesTheBadParameterBeforeAnyWork) {
  TableBakeRequest r;
  r.output = (fresh_test_dir() / "t.exr").string();
  r.type = "lambert";
  r.params = R"({"albedo": 1})";
  EXPECT_NE(error_of([&] { plan_table_bake(r); }).find("'--params.albedo': unknown key"),
            std::string::npos);
  r.type = "nosuch";
  r.params = "{}";
  EXPECT_NE(error_of([&] { plan_table_bake(r); }).find("unknown material 'nosuch'"),
            std::string::npos);
  r.output = (fresh_test_dir() / "t.png").string();
  r.type = "lambert";
  EXPECT_NE(error_of([&] { plan_table_bake(r); }), "");
}

TEST(TableRequest, RunTabulatesALambertianWithItsAlbedoAndNamesIt) {
  TableBakeRequest r;
  r.output = (fresh_test_dir() / "t.exr").string();
  r.type = "lambert";
  r.params = R"({"reflectance": [0.5, 0.4, 0.3]})";
  r.resolution = 4;
  r.samples = 4;
  const TabulatedBsdfTable t = run_table_bake(plan_table_bake(r), no_progress());
  EXPECT_EQ(t.kind, "fiber");
  EXPECT_EQ(t.metadata.at("source").rfind("analytic lambert ", 0), 0u);
  // A Lambertian reflects its reflectance for light along the normal, and transmits nothing.
  const auto a = table_info(t, r.output);
  EXPECT_NEAR(a["reflectance_normal_incidence"][0].get<double>(), 0.5, 0.01);
  EXPECT_NEAR(a["reflectance_normal_incidence"][2].get<double>(), 0.3, 0.01);
  EXPECT_NEAR(a["transmittance_normal_incidence"][1].get<double>(), 0.0, 1e-12);
}
