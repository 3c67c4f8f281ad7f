// The report folder (verify/report.h): written whole or not at all, never over something else.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>

#include "test_util.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/materials/bsdf_table.h"
#include "weft/verify/report.h"

namespace fs = std::filesystem;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace weft {
namespace {

VerifyReport tiny_report() {
  VerifyReport r;
  r.measured.file = "m.csv";
  r.measured.curves.push_back(MeasuredCurve{0, {0, 30}, {Rgb(0.5), Rgb(0.4)}});
  ModelCurves m;
  m.key = m.label = "classic";
  m.beta = {{Rgb(1.0), Rgb(0.8)}};
  m.beta_err = {{Rgb(0.1), Rgb(0.1)}};
  m.normalization = Rgb(0.5);
  m.absolute.push_back({});
  m.normalized.push_back({});
  r.models.push_back(m);
  return r;
}

TEST(VerifyReportFiles, AllOrNone) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  // A failing plot leaves nothing, not even a staging folder.
  EXPECT_THROW(write_verify_report(out, tiny_report(),
                                   [](const fs::path&) { throw Error("plot", "", "failed"); }),
               Error);
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
  // A good run writes every file; a second run replaces it.
  for (int k = 0; k < 2; ++k) {
    write_verify_report(out, tiny_report(),
                        [](const fs::path& s) { write_text_atomically(s / "p.png", "PNG"); });
    for (const char* f : {"inplane.csv", "metrics.json", "index.html", "p.png"})
      EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  std::ifstream csv(out / "inplane.csv");
  std::stringstream ss;
  ss << csv.rdbuf();
  // The classic row at view 30: beta 0.8, err 0.1, normalized 0.4 with factor 0.5.
  EXPECT_NE(ss.str().find("0,30,classic,R,0.8,0.1,0.4,0.5"), std::string::npos) << ss.str();
  // A folder holding something else is refused and left alone.
  const fs::path other = dir / "other";
  fs::create_directory(other);
  write_text_atomically(other / "keep.txt", "x");
  EXPECT_NE(error_of([&] {
              write_verify_report(other, tiny_report(), [](const fs::path&) {});
            }).find("refusing"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(other / "keep.txt"));
  EXPECT_FALSE(fs::exists(other / "metrics.json"));
}

// Each model's fabric table gets weft view's page beside index.html, which links it; a report
// without the viewer says why it has none.
TEST(VerifyReportFiles, EachFabricTableGetsAPreviewPageLinkedFromTheIndex) {
  const fs::path dir = fresh_test_dir();
  VerifyReport r = tiny_report();
  r.classic_fabric = TabulatedBsdfTable::from_function(
      2, 3,
      [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        for (double& x : v) x = (wo.z > 0 && wi.z > 0) ? 0.4 / kPi : 0.0;
      },
      1, 1);
  std::string skipped;
  r.previews = write_verify_previews(dir, r, &skipped);
  if (!skipped.empty()) {
    EXPECT_TRUE(r.previews.empty());
    EXPECT_NE(skipped.find("scripts/install-viewer.sh"), std::string::npos) << skipped;
    r.previews_skipped = skipped;
    EXPECT_NE(verify_index_html(r, {}).find("No 3-D previews"), std::string::npos);
    GTEST_SKIP() << "three.js for the preview is not installed: " << skipped;
  }
  ASSERT_EQ(r.previews.size(), 1u);  // no computed table in this report
  EXPECT_EQ(r.previews[0].file, "preview-classic.html");
  const std::string page = testing::slurp(dir / "preview-classic.html");
  EXPECT_NE(page.find("id='weft-glb'"), std::string::npos) << "the page shows the material";
  EXPECT_NE(page.find("<g class='weft-incidence'"), std::string::npos);
  const std::string index = verify_index_html(r, {});
  EXPECT_NE(index.find("<a href=\"preview-classic.html\">"), std::string::npos);
  // Linked, not embedded: the index holds neither three.js nor the .glb.
  EXPECT_EQ(index.find("weft-glb"), std::string::npos);
  EXPECT_LT(index.size(), page.size() / 10);
}

// --colour-from measured: each unfitted model's absolute figure is its calibrated one
// (models.<m>.calibrated, docs/colour.md); a fitted model sets its own colour and has none, and a
// run not calibrated has none at all.
TEST(VerifyReportFiles, CalibratedRunGivesEachUnfittedModelItsCalibratedFigure) {
  VerifyReport r = tiny_report();
  ModelCurves c = r.models[0];
  c.key = "computed_raytrace";
  c.beta = {{Rgb(0.5), Rgb(0.4)}};
  r.models.push_back(c);
  c.key = "classic_fitted";
  r.models.push_back(c);
  for (auto& m : r.models) m.figures = model_figures(m.beta, {}, r.measured, {0, 0});
  for (const bool calibrated : {false, true}) {
    r.colour_calibrated = calibrated;
    const auto j = nlohmann::json::parse(verify_metrics_json(r));
    const auto& models = j.at("models");
    for (const char* key : {"classic", "computed_raytrace"}) {
      ASSERT_EQ(models.at(key).contains("calibrated"), calibrated) << key;
      if (calibrated)
        EXPECT_EQ(models.at(key).at("calibrated"), models.at(key).at("absolute")) << key;
    }
    EXPECT_FALSE(models.at("classic_fitted").contains("calibrated"));
    EXPECT_EQ(j.contains("computed_calibrated_rms_log"), calibrated);
    EXPECT_EQ(j.at("colour_calibrated"), calibrated);
  }
}

// Against camera RGB a calibrated run's absolute figure is judged: both models' colour came from
// the measurement's own reading, in its own space; uncalibrated it stays not comparable.
TEST(VerifyReportFiles, CalibratedRunJudgesTheAbsoluteFigureInCameraRgb) {
  for (const bool calibrated : {false, true}) {
    VerifyReport r = tiny_report();
    r.measured.colour_space = MeasuredColourSpace::kCamera;
    r.colour_calibrated = calibrated;
    ModelCurves c = r.models[0];
    c.key = "computed_raytrace";
    c.beta = {{Rgb(0.5), Rgb(0.4)}};
    r.models.push_back(c);
    for (auto& m : r.models) m.figures = model_figures(m.beta, {}, r.measured, {0, 0});
    const auto j = nlohmann::json::parse(verify_metrics_json(r));
    EXPECT_EQ(j.at("absolute_comparable"), calibrated);
    ASSERT_EQ(j.at("verdict").at("absolute").size(), 1u);
    const auto& v = j.at("verdict").at("absolute")[0];
    EXPECT_EQ(v.at("comparable"), calibrated);
    EXPECT_EQ(v.at("text").get<std::string>().find("calibrated") != std::string::npos, calibrated);
    EXPECT_EQ(
        j.at("models").at("computed_raytrace").at("uncertainty").at("absolute").at("comparable"),
        calibrated);
    EXPECT_EQ(verify_index_html(r, {}).find("(not comparable)") != std::string::npos, !calibrated);
  }
}

// Against camera (or unknown) RGB the absolute figures and the measurement's colour are marked
// not comparable in metrics.json and on the page; the shape and the paper's figures are not.
TEST(VerifyReportFiles, CameraRgbMarksAbsoluteFiguresNotComparable) {
  for (const auto space :
       {MeasuredColourSpace::kCamera, MeasuredColourSpace::kUnknown, MeasuredColourSpace::kSrgb}) {
    VerifyReport r = tiny_report();
    r.measured.colour_space = space;
    // Two models (the classic above and a computed one half as bright), scored.
    ModelCurves c = r.models[0];
    c.key = "computed_raytrace";
    c.beta = {{Rgb(0.5), Rgb(0.4)}};
    r.models.push_back(c);
    for (auto& m : r.models) m.figures = model_figures(m.beta, {}, r.measured, {0, 0});
    ColourEntry e;
    e.name = "measured";
    e.rgb = Rgb(0.5);
    e.comparable = absolute_comparable(space);
    r.colours.push_back(e);
    const auto j = nlohmann::json::parse(verify_metrics_json(r));
    const bool srgb = space == MeasuredColourSpace::kSrgb;
    EXPECT_EQ(j.at("colour_space"), colour_space_name(space));
    EXPECT_EQ(j.at("absolute_comparable"), srgb);
    const auto& u = j.at("models").at("computed_raytrace").at("uncertainty");
    EXPECT_EQ(u.at("absolute").at("comparable"), srgb);
    EXPECT_EQ(u.at("shape").at("comparable"), true);
    EXPECT_EQ(u.at("paper_normalized").at("comparable"), true);
    ASSERT_EQ(j.at("verdict").at("absolute").size(), 1u);
    EXPECT_EQ(j.at("verdict").at("absolute")[0].at("comparable"), srgb);
    EXPECT_EQ(j.at("verdict").at("shape")[0].at("comparable"), true);
    EXPECT_EQ(j.at("colour_table")[0].at("comparable"), srgb);
    const std::string html = verify_index_html(r, {});
    EXPECT_EQ(html.find("not comparable") != std::string::npos, !srgb);
    // The verdict leads the page, above the plots.
    EXPECT_LT(html.find("<h2>Verdict</h2>"), html.find("<h2>In-plane curves</h2>"));
    // One page: the document ends once, and every table opened is closed.
    EXPECT_EQ(html.find("</html>"), html.rfind("</html>"));
    EXPECT_EQ(html.size() - html.find("</body></html>\n"), std::string("</body></html>\n").size());
    size_t opened = 0, closed = 0;
    for (size_t p = 0; (p = html.find("<table", p)) != std::string::npos; ++p) ++opened;
    for (size_t p = 0; (p = html.find("</table>", p)) != std::string::npos; ++p) ++closed;
    EXPECT_EQ(opened, closed);
  }
}

}  // namespace
}  // namespace weft
