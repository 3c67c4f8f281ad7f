// weft verify --suite (verify/suite.h): the suite file is read and checked field by field, every
// bundled fabric plans, a fabric's request carries its own inputs, and the summary reads each
// report's figures back (a failed fabric is a row that says why).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
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
      "computed_raytrace": {"normalized": {"rms_log": 0.73},
          "absolute": {"rms_log": 0.55}, "log_floored_points": 40,
          "shape": {"rms_log": 0.31, "rms_log_channel": {"R": 0.25, "G": 0.33, "B": 0.35}},
          "uncertainty": {"shape": {"seed_se": 0.004, "fit_min": 0.28, "fit_max": 0.39}}},
      "classic": {"shape": {"rms_log": 0.66, "rms_log_channel": {"R": 0.7, "G": 0.61, "B": 0.66}},
                  "normalized": {"rms_log": 0.75},
                  "absolute": {"rms_log": 1.5}}},
      "verdict": {"shape": [{"a": "computed_raytrace", "b": "classic", "resolved": true,
                             "closer": "computed_raytrace", "text": "Shape: computed wins"}],
                  "absolute": [{"a": "computed_raytrace", "b": "classic", "resolved": false,
                                "comparable": false, "text": "Absolute: not resolved"}]}})");
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
  // The counts per figure, on top: the shape's one each way, the failed fabric without a verdict.
  EXPECT_NE(all_html.find("<b>shape</b>: <span class=\"computed\">computed 1</span> <span "
                          "class=\"classic\">classic 0</span> <span class=\"tie\">tie 1</span> "
                          "<span class=\"no_model\">no model describes 1</span> <span "
                          "class=\"none\">without a verdict 1</span>"),
            std::string::npos);
  EXPECT_NE(all_html.find("<td class=\"v no_model\""), std::string::npos);
  EXPECT_NE(all_html.find("<td class=\"v tie\""), std::string::npos);
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
  EXPECT_EQ(j.at("fabrics")[0].at("closer").at("absolute"), "not_comparable");
  EXPECT_DOUBLE_EQ(g.at("classic").at("shape_rms_log_channel").at("G").get<double>(), 0.61);
  EXPECT_EQ(j.at("figure_summary").at("absolute").at("not_comparable"), 1);
  const std::string html = verify_suite_html(s, {good, bad});
  EXPECT_NE(html.find("<a href=\"good/index.html\">good</a>"), std::string::npos);
  EXPECT_NE(html.find("failed: the sample fails"), std::string::npos);
  // Every model's figures, whole, in the shape cell's title; the verdict's text with them.
  EXPECT_NE(
      html.find("Figures: computed (ray trace) 0.310 &plusmn; 0.004 (fits 0.280&ndash;0.390)"),
      std::string::npos);
  EXPECT_NE(html.find("title=\"Shape: computed wins "), std::string::npos);
  // Not comparable (camera RGB): said in words, the figures in brackets.
  EXPECT_NE(html.find("not comparable <small>(0.550 / 1.500)</small>"), std::string::npos);
  EXPECT_NE(html.find("Computed table: 0 components clipped, 1092 outside the sRGB gamut (kept), "
                      "40 points floored"),
            std::string::npos);
  EXPECT_EQ(j.at("fabrics")[0].at("computed_gamut_clipped_components"), 0);
  EXPECT_EQ(j.at("fabrics")[0].at("computed_out_of_gamut_components"), 1092);
  // Each figure's verdict has its cell now, the absolute one's text in its title.
  EXPECT_NE(html.find("title=\"Absolute: not resolved "), std::string::npos);
  const std::string text = verify_suite_text({good, bad});
  EXPECT_NE(text.find("computed closer on 1, classic closer on 0"), std::string::npos);
  EXPECT_NE(text.find("good: Shape: computed wins"), std::string::npos);
}

// A fabric's metrics.json as a report writes it (docs/verify.md), trimmed to what the suite page
// reads: the computed model closer in shape, the classic in the paper's figure, a tie in the
// absolute one.
nlohmann::json scoreboard_metrics() {
  return nlohmann::json::parse(R"({"absolute_comparable": true, "models": {
      "computed_raytrace": {"shape": {"rms_log": 0.31,
                                      "rms_log_channel": {"R": 0.25, "G": 0.33, "B": 0.35}},
                            "normalized": {"rms_log": 0.8}, "absolute": {"rms_log": 0.5}},
      "classic": {"shape": {"rms_log": 0.66, "rms_log_channel": {"R": 0.7, "G": 0.61, "B": 0.66}},
                  "normalized": {"rms_log": 0.7}, "absolute": {"rms_log": 0.52}}},
      "verdict": {
        "shape": [{"a": "computed_raytrace", "b": "classic", "resolved": true,
                   "closer": "computed_raytrace", "text": "Shape: computed closer"}],
        "paper_normalized": [{"a": "computed_raytrace", "b": "classic", "resolved": true,
                              "closer": "classic", "text": "Paper's: classic closer"}],
        "absolute": [{"a": "computed_raytrace", "b": "classic", "resolved": false, "tie": true,
                      "text": "Absolute: a tie"}]}})");
}

SuiteRow scoreboard_row(const std::string& name, const std::string& known) {
  SuiteRow r{{name, "m.csv", "red-cotton", "", "", "", "srgb", known}, scoreboard_metrics(), ""};
  return r;
}

TEST(VerifySuitePage, CountsFirstThenACompactRowPerFabric) {
  VerifySuite s;
  s.title = "board";
  SuiteRow failed{{"broken", "m.csv", "red-cotton", "", "", "", "", "k"}, nullptr, "it failed"};
  const std::string html =
      verify_suite_html(s, {scoreboard_row("alpha", "k"), scoreboard_row("beta", "k"), failed});
  const size_t counts = html.find("<p class=\"counts\""), table = html.find("<table");
  ASSERT_NE(counts, std::string::npos);
  ASSERT_NE(table, std::string::npos);
  EXPECT_LT(counts, table);
  // Per figure: two fabrics each way, the failed one without a verdict.
  EXPECT_NE(html.find("<b>shape</b>: <span class=\"computed\">computed 2</span> <span "
                      "class=\"classic\">classic 0</span>"),
            std::string::npos);
  EXPECT_NE(html.find("<b>paper's</b>: <span class=\"computed\">computed 0</span> <span "
                      "class=\"classic\">classic 2</span>"),
            std::string::npos);
  EXPECT_NE(html.find("<b>absolute</b>: <span class=\"computed\">computed 0</span> <span "
                      "class=\"classic\">classic 0</span> <span class=\"tie\">tie 2</span>"),
            std::string::npos);
  EXPECT_NE(html.find("without a verdict 1"), std::string::npos);
  for (const std::string name : {"alpha", "beta", "broken"})
    EXPECT_NE(html.find("<a href=\"" + name + "/index.html\">" + name + "</a>"), std::string::npos)
        << name;
  // Each verdict cell: its class (the colour) and its word, then computed / classic.
  const std::string alpha = html.substr(html.find("alpha/index.html"));
  const auto cell = [&](const std::string& css, const std::string& text) {
    const size_t open = alpha.find("<td class=\"v " + css + "\"");
    if (open == std::string::npos) return std::string();
    return alpha.substr(alpha.find('>', open) + 1, text.size());
  };
  EXPECT_EQ(cell("computed", "computed <small>0.310 / 0.660</small>"),
            "computed <small>0.310 / 0.660</small>");
  EXPECT_EQ(cell("classic", "classic <small>0.800 / 0.700</small>"),
            "classic <small>0.800 / 0.700</small>");
  EXPECT_EQ(cell("tie", "tie <small>0.500 / 0.520</small>"), "tie <small>0.500 / 0.520</small>");
  // The shape error per channel, computed R G B then classic R G B.
  EXPECT_NE(alpha.find("<td class=\"ch\">0.250</td><td class=\"ch\">0.330</td><td "
                       "class=\"ch\">0.350</td><td class=\"ch\">0.700</td><td "
                       "class=\"ch\">0.610</td><td class=\"ch\">0.660</td>"),
            std::string::npos);
  // What is known, short: the preset and its dyes (fiber/presets/red-cotton.json).
  EXPECT_NE(alpha.find("fiber red-cotton &middot; congo-red 2 % + curcumin 0.2 % owf"),
            std::string::npos);
  EXPECT_NE(html.find("failed: it failed"), std::string::npos);
  // One line per row at a fixed height.
  for (const char* rule :
       {"white-space:nowrap", "text-overflow:ellipsis", "line-height:1.3", "font:13px/1.3"})
    EXPECT_NE(html.find(rule), std::string::npos) << rule;
}

// --colour-from measured over a suite: each fabric is calibrated to its own measurement (the
// request carries it), and the page names the absolute figure "calibrated", judges it in camera
// RGB too (the colour came from the measurement itself) and shows the recipe as matched.
TEST(VerifySuitePage, ACalibratedSuiteJudgesTheCalibratedFigureAndShowsTheMatchedRecipe) {
  VerifyRequest base;
  base.colour_from = "measured";
  const SuiteFabric fabric{"a", "m.csv", "red-cotton", "", "", "", "camera", "k"};
  EXPECT_EQ(suite_request(fabric, base, "/tmp/out").colour_from, "measured");

  VerifySuite s;
  s.title = "calibrated";
  SuiteRow row = scoreboard_row("alpha", "k");
  row.fabric.colour_space = "camera";
  row.metrics["absolute_comparable"] = false;
  row.metrics["colour_calibrated"] = true;
  row.metrics["models"]["computed_raytrace"]["calibrated"] = {{"rms_log", 0.5}};
  row.metrics["verdict"]["absolute"] = nlohmann::json::parse(
      R"([{"a": "computed_raytrace", "b": "classic", "resolved": true, "comparable": true,
           "closer": "computed_raytrace", "text": "Absolute: computed closer [calibrated]"}])");
  row.metrics["colour_match"] = nlohmann::json::parse(
      R"j({"basis": "the recipe's dyes (% owf)", "delta_e00": 5.69, "outside_reach": true,
          "dye_scale": [{"dye": "congo-red", "scale": 0.75}, {"dye": "curcumin", "scale": 0.34}]})j");
  const auto j = nlohmann::json::parse(verify_suite_json(s, {row}));
  EXPECT_EQ(j.at("colour_calibrated"), true);
  EXPECT_EQ(j.at("fabrics")[0].at("closer").at("absolute"), "computed");
  EXPECT_EQ(j.at("figure_summary").at("absolute").at("computed_closer"), 1);
  EXPECT_DOUBLE_EQ(j.at("fabrics")[0]
                       .at("models")
                       .at("computed_raytrace")
                       .at("calibrated_rms_log")
                       .get<double>(),
                   0.5);
  EXPECT_EQ(j.at("fabrics")[0].at("colour_match").at("dyes"),
            "congo-red 0.75 % + curcumin 0.34 % owf");
  const std::string html = verify_suite_html(s, {row});
  EXPECT_NE(html.find("<b>calibrated</b>: <span class=\"computed\">computed 1</span>"),
            std::string::npos);
  EXPECT_EQ(html.find("<b>absolute</b>:"), std::string::npos);
  EXPECT_NE(html.find("<th>calibrated</th>"), std::string::npos);
  EXPECT_NE(html.find("matched congo-red 0.75 % + curcumin 0.34 % owf (&Delta;E00 5.69, out of "
                      "reach)"),
            std::string::npos);
  const std::string text = verify_suite_text({row});
  EXPECT_NE(text.find("calibrated"), std::string::npos);
  EXPECT_NE(text.find("Calibrated (each fabric's colour from its measurement's d/8 reading), "
                      "computed vs classic: computed closer on 1"),
            std::string::npos);
  // Without calibration the same page keeps "absolute".
  EXPECT_NE(verify_suite_html(s, {scoreboard_row("beta", "k")}).find("<th>absolute</th>"),
            std::string::npos);
}

TEST(VerifySuitePage, PathsAreShownRelativeNeverAbsolute) {
  const fs::path dir = fresh_test_dir();
  fs::create_directories(dir / "suite" / "fibers");
  fs::copy_file(fs::path(WEFT_SOURCE_DIR) / "verify/data/suite/cotton-blue.json",
                dir / "suite" / "fibers" / "blue.json");
  write(dir / "suite" / "m.csv", "theta_i_deg,theta_o_deg\n");
  const fs::path fiber = fs::absolute(dir / "suite" / "fibers" / "blue.json");
  ASSERT_TRUE(fiber.is_absolute());
  write(dir / "suite" / "s.json", R"({"title": "t", "fabrics": [{"name": "a", "measured": "m.csv",
      "fiber": ")" + fiber.string() + R"(", "known": "k"}]})");
  const VerifySuite s = read_verify_suite(dir / "suite" / "s.json");
  ASSERT_EQ(s.fabrics[0].fiber, fiber.string());  // kept as given
  const std::string html = verify_suite_html(s, {{s.fabrics[0], scoreboard_metrics(), ""}});
  EXPECT_NE(html.find("fiber fibers/blue.json &middot; evans-blue 2 % owf"), std::string::npos);
  EXPECT_NE(html.find("Measured: m.csv,"), std::string::npos);
  EXPECT_EQ(html.find(fs::absolute(dir).string()), std::string::npos);
  EXPECT_EQ(html.find(WEFT_SOURCE_DIR), std::string::npos);

  // The bundled suite: its weave climbs out of verify/data, so it is shown from the data's root.
  const VerifySuite bundled = read_verify_suite(bundled_verify_suite());
  std::vector<SuiteRow> rows;
  for (const SuiteFabric& f : bundled.fabrics) rows.push_back({f, nullptr, "not run here"});
  const std::string page = verify_suite_html(bundled, rows);
  EXPECT_NE(page.find("fiber suite/cotton-blue.json &middot; evans-blue 2 % owf &middot; weave "
                      "scenes/examples/red-cotton-weave.json"),
            std::string::npos);
  EXPECT_NE(page.find("Measured: materials/data/measured/merl-blue-fabric/inplane.csv"),
            std::string::npos);
  EXPECT_EQ(page.find(WEFT_SOURCE_DIR), std::string::npos);
  EXPECT_EQ(page.find(fs::absolute(bundled.file).parent_path().string()), std::string::npos);
}

std::string suite_command_output(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  pclose(pipe);
  return out;
}

// The page of a 24-row suite, drawn by a browser at 1400 x 900: at least 20 rows are on screen
// with the counts and the header above them. A script appended to a copy of the page counts the
// rows whose bottom is within the window, and the DOM the browser dumps carries the count.
TEST(VerifySuitePage, TwentyRowsFitAScreenOf1400By900) {
  if (suite_command_output("command -v chromium 2>/dev/null").empty())
    GTEST_SKIP() << "chromium is not installed: the page's layout is not measured";
  VerifySuite s;
  s.title = "Weft's bundled measured fabrics";
  std::vector<SuiteRow> rows;
  const std::string known(400, 'k');  // longer than any cell: cut with an ellipsis
  for (int k = 0; k < 24; ++k) {
    rows.push_back(scoreboard_row("merl-fabric-with-a-long-name-" + std::to_string(k), known));
    if (k % 8 == 7) rows.back().error = std::string(300, 'e');
  }
  std::string page = verify_suite_html(s, rows);
  const std::string script =
      "<script>const rows=[...document.querySelectorAll('tbody tr')];"
      "document.body.setAttribute('data-rows',String(rows.length));"
      "document.body.setAttribute('data-rows-visible',String(rows.filter("
      "r=>r.getBoundingClientRect().bottom<=900).length));</script>";
  page.insert(page.rfind("</body>"), script);
  const fs::path file = fs::absolute(fresh_test_dir() / "index.html");
  write(file, page);
  const std::string dom = suite_command_output(
      "chromium --headless --disable-gpu --no-sandbox --window-size=1400,900 --dump-dom 'file://" +
      file.string() + "' 2>/dev/null");
  std::smatch all, visible;
  ASSERT_TRUE(std::regex_search(dom, all, std::regex("data-rows=\"(\\d+)\"")))
      << dom.substr(0, 500);
  EXPECT_EQ(std::stoi(all[1]), 24);
  ASSERT_TRUE(std::regex_search(dom, visible, std::regex("data-rows-visible=\"(\\d+)\"")));
  EXPECT_GE(std::stoi(visible[1]), 20);
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
