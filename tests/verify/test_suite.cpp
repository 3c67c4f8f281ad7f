// weft verify --suite (verify/suite.h): the suite file is read and checked field by field, every
// bundled fabric plans, a fabric's request carries its own inputs, and the summary reads each
// report's figures back (a failed fabric is a row that says why).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "test_util.h"
#include "weft/verify/suite.h"

namespace fs = std::filesystem;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace weft {
namespace {

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// A suite file in 'dir' with one fabric whose fields are 'fabric' (JSON members), and a measured
// file beside it.
fs::path suite_with(const fs::path& dir, const std::string& fabric) {
  write(dir / "m.csv", "theta_i_deg,theta_o_deg\n");
  const fs::path f = dir / "suite.json";
  write(f, "{\"title\": \"t\", \"fabrics\": [{" + fabric + "}]}");
  return f;
}

TEST(VerifySuite, EveryBundledFabricPlans) {
  const VerifySuite s = read_verify_suite(bundled_verify_suite());
  ASSERT_GE(s.fabrics.size(), 2u);
  VerifyRequest base;
  base.quality = "draft";
  for (const SuiteFabric& f : s.fabrics) {
    EXPECT_FALSE(f.known.empty()) << f.name;
    const VerifyRequest r = suite_request(f, base, "/tmp/out");
    EXPECT_EQ(r.output, "/tmp/out/" + f.name);
    EXPECT_EQ(r.quality, "draft");
    EXPECT_EQ(r.measured, f.measured);
    const VerifyPlan p = plan_verify(r);  // inputs read and checked
    EXPECT_FALSE(p.measured.curves.empty()) << f.name;
  }
}

TEST(VerifySuite, FieldsAreCheckedAndNamed) {
  const fs::path dir = fresh_test_dir();
  const std::string ok = R"("name": "a", "measured": "m.csv", "fiber": "red-cotton", "known": "k")";
  const VerifySuite s = read_verify_suite(suite_with(dir, ok));
  ASSERT_EQ(s.fabrics.size(), 1u);
  EXPECT_EQ(fs::path(s.fabrics[0].measured), (dir / "m.csv").lexically_normal());
  EXPECT_EQ(s.fabrics[0].fiber, "red-cotton");  // a preset: no such file

  const auto error = [&](const std::string& fabric) {
    return error_of([&] { read_verify_suite(suite_with(dir, fabric)); });
  };
  EXPECT_NE(error(ok + R"(, "colour": "red")").find("colour"), std::string::npos);
  EXPECT_NE(error(R"("name": "../x", "measured": "m.csv", "fiber": "f", "known": "k")")
                .find("fabrics[0].name"),
            std::string::npos);
  EXPECT_NE(error(R"("name": "a", "measured": "none.csv", "fiber": "f", "known": "k")")
                .find("fabrics[0].measured"),
            std::string::npos);
  EXPECT_NE(error(ok + R"(, "colour_space": "xyz")").find("fabrics[0].colour_space"),
            std::string::npos);
  EXPECT_NE(error(R"("name": "a", "measured": "m.csv", "fiber": "f")").find("known"),
            std::string::npos);
  write(dir / "twice.json", "{\"title\": \"t\", \"fabrics\": [{" + ok + "}, {" + ok + "}]}");
  EXPECT_NE(error_of([&] { read_verify_suite(dir / "twice.json"); }).find("fabrics[1].name"),
            std::string::npos);
  write(dir / "empty.json", R"({"title": "t", "fabrics": []})");
  EXPECT_NE(error_of([&] { read_verify_suite(dir / "empty.json"); }).find("fabrics"),
            std::string::npos);
  EXPECT_NE(error_of([&] { read_verify_suite(dir / "missing.json"); }).find("missing.json"),
            std::string::npos);
}

TEST(VerifySuite, SummaryReadsEachReportAndSaysWhyOneFailed) {
  VerifySuite s;
  s.title = "two";
  SuiteRow good{{"good", "m.csv", "red-cotton", "", "", "", "camera", "a red cloth"}, {}, ""};
  // The keys a report writes (docs/verify.md): figures per model with their uncertainty, and
  // the verdict per figure.
  good.metrics = nlohmann::json::parse(R"({"absolute_comparable": false,
      "fabric_table_gamut_clipped_components": 0,
      "fabric_table_out_of_gamut_components": 1092, "models": {
      "computed_raytrace": {"shape": {"rms_log": 0.31}, "normalized": {"rms_log": 0.73},
          "absolute": {"rms_log": 0.55}, "log_floored_points": 40,
          "uncertainty": {"shape": {"seed_se": 0.004, "fit_min": 0.28, "fit_max": 0.39}}},
      "classic": {"shape": {"rms_log": 0.66}, "normalized": {"rms_log": 0.75},
                  "absolute": {"rms_log": 1.5}}},
      "verdict": {"shape": [{"a": "computed_raytrace", "b": "classic", "resolved": true,
                             "closer": "computed_raytrace", "text": "Shape: computed wins"}],
                  "absolute": [{"a": "computed_raytrace", "b": "classic", "resolved": false,
                                "text": "Absolute: not resolved"}]}})");
  SuiteRow bad{{"bad", "m.csv", "red-cotton", "", "", "", "", "k"}, nullptr, "the sample fails"};
  // A tie, and a sample no model describes (a glossy film: every model above 1 in shape).
  SuiteRow tie{{"tie", "m.csv", "red-cotton", "", "", "", "srgb", "k"}, {}, ""};
  tie.metrics = nlohmann::json::parse(R"({"verdict": {"shape": [{"a": "computed_raytrace",
      "b": "classic", "resolved": false, "tie": true, "text": "Shape: a tie"}]}})");
  SuiteRow film{{"film", "m.csv", "red-cotton", "", "", "", "srgb", "k"}, {}, ""};
  film.metrics = nlohmann::json::parse(R"({"verdict": {"no_model_describes": true,
      "shape": [{"a": "computed_raytrace", "b": "classic", "resolved": false, "tie": false,
                 "no_model_describes": true, "text": "Shape: no model here describes it"}]}})");
  const auto all = nlohmann::json::parse(verify_suite_json(s, {good, bad, tie, film}));
  EXPECT_EQ(all.at("fabrics")[2].at("shape_closer"), "tie");
  EXPECT_EQ(all.at("fabrics")[3].at("shape_closer"), "no_model");
  EXPECT_EQ(all.at("fabrics")[3].at("no_model_describes"), true);
  EXPECT_EQ(all.at("shape_summary").at("tie"), 1);
  EXPECT_EQ(all.at("shape_summary").at("no_model_describes"), 1);
  EXPECT_EQ(all.at("shape_summary").at("unresolved"), 2);  // both name no closer model
  const std::string all_html = verify_suite_html(s, {good, bad, tie, film});
  EXPECT_NE(all_html.find("a tie on 1, no model describes the sample on 1 fabric(s)"),
            std::string::npos);
  EXPECT_NE(all_html.find("<b>No model here describes this sample.</b>"), std::string::npos);
  const auto j = nlohmann::json::parse(verify_suite_json(s, {good, bad}));
  EXPECT_EQ(j.at("report"), "weft verify suite");
  const auto& g = j.at("fabrics")[0].at("models");
  EXPECT_DOUBLE_EQ(g.at("computed_raytrace").at("shape_rms_log").get<double>(), 0.31);
  EXPECT_DOUBLE_EQ(g.at("classic").at("absolute_rms_log").get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(g.at("computed_raytrace").at("shape_seed_se").get<double>(), 0.004);
  EXPECT_DOUBLE_EQ(g.at("computed_raytrace").at("shape_fit_max").get<double>(), 0.39);
  EXPECT_TRUE(g.at("classic").at("shape_seed_se").is_null());  // not in that report
  EXPECT_FALSE(g.contains("computed_summation"));              // not in that report
  EXPECT_EQ(j.at("fabrics")[0].at("shape_closer"), "computed");
  EXPECT_EQ(j.at("fabrics")[0].at("shape_verdicts"),
            nlohmann::json::array({"Shape: computed wins"}));
  EXPECT_EQ(j.at("fabrics")[0].at("absolute_comparable"), false);
  EXPECT_EQ(j.at("fabrics")[1].at("error"), "the sample fails");
  EXPECT_EQ(j.at("shape_summary").at("computed_closer"), 1);
  EXPECT_EQ(j.at("shape_summary").at("without_verdict"), 1);  // the failed one
  const std::string html = verify_suite_html(s, {good, bad});
  EXPECT_NE(html.find("good/index.html"), std::string::npos);
  EXPECT_NE(html.find("failed: the sample fails"), std::string::npos);
  EXPECT_NE(html.find("0.310 &plusmn; 0.004 <small>(fits 0.280&ndash;0.390)"), std::string::npos);
  EXPECT_NE(html.find("<small>(0.550)</small>"), std::string::npos);  // not comparable
  EXPECT_NE(html.find("Shape: computed wins"), std::string::npos);
  EXPECT_NE(html.find("computed table: 0 components clipped, 1092 outside the sRGB gamut (kept), "
                      "40 points floored"),
            std::string::npos);
  EXPECT_EQ(j.at("fabrics")[0].at("computed_gamut_clipped_components"), 0);
  EXPECT_EQ(j.at("fabrics")[0].at("computed_out_of_gamut_components"), 1092);
  EXPECT_EQ(html.find("Absolute: not resolved"), std::string::npos);  // the shape verdicts only
  EXPECT_NE(html.find("computed closer on 1, classic closer on 0"), std::string::npos);
  EXPECT_NE(verify_suite_text({good, bad}).find("good: Shape: computed wins"), std::string::npos);
}

TEST(VerifySuite, OutputIsNewEmptyOrAnEarlierSuite) {
  const fs::path dir = fresh_test_dir();
  check_suite_output(dir / "new");
  check_suite_output(dir);  // empty
  write(dir / "suite.json", R"({"report": "weft verify suite"})");
  check_suite_output(dir);
  write(dir / "suite.json", R"({"report": "something else"})");
  EXPECT_NE(error_of([&] { check_suite_output(dir); }).find("-o"), std::string::npos);
  EXPECT_NE(error_of([&] { check_suite_output(dir / "suite.json"); }).find("not a directory"),
            std::string::npos);
}

}  // namespace
}  // namespace weft
