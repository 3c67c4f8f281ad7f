// The figures of `weft verify` as tools/plot_verify.py lays them out, read from its --describe
// JSON: one figure per incidence (files sorted by incidence), the absolute row on a log axis with
// the values it cannot draw counted, one legend per figure outside every panel, the mirror
// direction labelled on every panel; the same figures from several processes. Skipped where
// /usr/bin/python3 has no matplotlib.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::fresh_test_dir;
using weft::testing::slurp;

namespace {

bool has_matplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

// inplane.csv as weft verify writes it (report.cpp): the incidences (0 and 30 degrees unless
// given), five views, the measurement and two models; the ray trace has a zero (drawable only on
// the linear axis) and a NaN (nowhere) in the R channel at 30 degrees.
void write_inputs(const fs::path& dir, const std::vector<int>& incidences = {0, 30}) {
  std::ofstream csv(dir / "inplane.csv");
  csv << "theta_i_deg,view_zenith_deg,model,channel,beta,beta_err,beta_norm,norm_factor\n";
  for (int ti : incidences)
    for (int view = -60; view <= 60; view += 30)
      for (const char* ch : {"R", "G", "B"}) {
        const double m = 0.1 + 0.001 * (view + 60);
        csv << ti << ',' << view << ",measured," << ch << ',' << m << ",0," << m << ",1\n";
        double rt = 0.05;
        if (ti == 30 && std::string(ch) == "R" && view == -60) rt = 0;
        const std::string rt_text = ti == 30 && std::string(ch) == "R" && view == 0
                                        ? std::string("nan")
                                        : std::to_string(rt);
        csv << ti << ',' << view << ",computed_raytrace," << ch << ',' << rt_text << ",0.001,"
            << rt_text << ",2\n";
        csv << ti << ',' << view << ",classic," << ch << ",0.2,0.002,0.1,0.5\n";
      }
  // metrics.json: only the models' labels are read.
  const char* metrics =
      "{\"models\": {\"computed_raytrace\": {\"label\": \"computed (ray trace)\"}, "
      "\"classic\": {\"label\": \"classic\"}}}";
  std::ofstream(dir / "metrics.json") << metrics;
}

// Whether two boxes [x0, y0, x1, y1] overlap.
bool overlap(const nlohmann::json& a, const nlohmann::json& b) {
  return a[0].get<double>() < b[2].get<double>() && b[0].get<double>() < a[2].get<double>() &&
         a[1].get<double>() < b[3].get<double>() && b[1].get<double>() < a[3].get<double>();
}

// The command that plots 'dir''s inputs into 'out' with 'extra' options, the script run by
// 'python' (a command line).
std::string plot_command(const fs::path& dir, const fs::path& out, const std::string& extra,
                         const std::string& python = "/usr/bin/python3") {
  return python + " '" + std::string(WEFT_SOURCE_DIR) + "/tools/plot_verify.py' " + extra + " '" +
         (dir / "inplane.csv").string() + "' '" + (dir / "metrics.json").string() + "' '" +
         out.string() + "' 2>/dev/null";
}

}  // namespace

// Figures drawn in several processes (weft passes its thread count) are the ones drawn in one:
// the same PNG bytes, the same layout in the incidences' order; where processes cannot be
// started, the script draws them itself. A count below one is refused. One process draws all
// three figures in one matplotlib figure, cleared between them; two draw the first before they
// fork and each draws one more in that figure; three draw each in a new figure.
TEST(PlotVerify, ProcessesDrawTheSameFigures) {
  if (!has_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 has no matplotlib";
  const fs::path dir = fresh_test_dir();
  write_inputs(dir, {0, 30, 60});
  for (const char* sub : {"one", "two", "three"}) fs::create_directories(dir / sub);
  const std::string one =
      plot_command(dir, dir / "one", "--describe '" + (dir / "one.json").string() + "'");
  ASSERT_EQ(std::system(one.c_str()), 0) << one;
  const std::pair<std::string, std::string> runs[] = {{"two", "2"}, {"three", "3"}};
  for (const auto& [sub, jobs] : runs) {
    const std::string many = plot_command(
        dir, dir / sub, "--jobs " + jobs + " --describe '" + (dir / sub).string() + ".json'");
    ASSERT_EQ(std::system(many.c_str()), 0) << many;
    EXPECT_EQ(nlohmann::json::parse(slurp(dir / "one.json")),
              nlohmann::json::parse(slurp(dir / (sub + ".json"))))
        << sub;
    for (const char* png : {"inplane-00.0deg.png", "inplane-30.0deg.png", "inplane-60.0deg.png"}) {
      const std::string a = slurp(dir / "one" / png), b = slurp(dir / sub / png);
      EXPECT_GT(a.size(), 1000u) << png;
      EXPECT_TRUE(a == b) << sub << " " << png;
    }
  }
  // Where no process can be started (a container without /dev/shm, say), this one draws them
  // all, the first before it tries: a wrapper runs the script with multiprocessing refusing.
  std::ofstream(dir / "no_processes.py") << "import multiprocessing, runpy, sys\n"
                                            "def refuse(*args, **kwargs):\n"
                                            "    raise OSError(38, 'Function not implemented')\n"
                                            "multiprocessing.get_context = refuse\n"
                                            "sys.argv = sys.argv[1:]\n"
                                            "runpy.run_path(sys.argv[0], run_name='__main__')\n";
  fs::create_directories(dir / "alone");
  const std::string alone =
      plot_command(dir, dir / "alone", "--jobs 2",
                   "/usr/bin/python3 '" + (dir / "no_processes.py").string() + "'");
  ASSERT_EQ(std::system(alone.c_str()), 0) << alone;
  for (const char* png : {"inplane-00.0deg.png", "inplane-30.0deg.png", "inplane-60.0deg.png"})
    EXPECT_TRUE(slurp(dir / "one" / png) == slurp(dir / "alone" / png)) << png;
  fs::create_directories(dir / "none");
  const std::string zero = plot_command(dir, dir / "none", "--jobs 0");
  EXPECT_NE(std::system(zero.c_str()), 0) << zero;
  EXPECT_TRUE(fs::is_empty(dir / "none"));
}

TEST(PlotVerify, OneReadableFigurePerIncidence) {
  if (!has_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 has no matplotlib";
  const fs::path dir = fresh_test_dir();
  write_inputs(dir);
  const std::string cmd = "/usr/bin/python3 '" + std::string(WEFT_SOURCE_DIR) +
                          "/tools/plot_verify.py' --describe '" + (dir / "layout.json").string() +
                          "' '" + (dir / "inplane.csv").string() + "' '" +
                          (dir / "metrics.json").string() + "' '" + dir.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto layout = nlohmann::json::parse(slurp(dir / "layout.json"));
  const auto& figures = layout.at("figures");
  ASSERT_EQ(figures.size(), 2u);
  EXPECT_EQ(figures[0].at("file"), "inplane-00.0deg.png");
  EXPECT_EQ(figures[1].at("file"), "inplane-30.0deg.png");
  for (const auto& f : figures) {
    const double ti = f.at("theta_i_deg");
    EXPECT_TRUE(fs::exists(dir / f.at("file").get<std::string>())) << f.at("file");
    const auto& panels = f.at("panels");
    ASSERT_EQ(panels.size(), 6u);  // normalized and absolute, R G B
    // One legend, its box inside the figure and clear of every panel.
    EXPECT_EQ(f.at("legends"), 1);
    EXPECT_TRUE(f.at("legend_outside_axes").get<bool>());
    const auto& legend = f.at("legend_box");
    EXPECT_GE(legend[0].get<double>(), 0.0);
    EXPECT_GE(legend[1].get<double>(), 0.0);
    EXPECT_LE(legend[2].get<double>(), 1.0);
    EXPECT_LE(legend[3].get<double>(), 1.0);
    for (const auto& p : panels) {
      EXPECT_FALSE(overlap(legend, p.at("axes_box"))) << f.at("file");
      EXPECT_EQ(p.at("yscale"), p.at("kind") == "absolute" ? "log" : "linear");
      EXPECT_EQ(p.at("mirror_deg").get<double>(), ti);
      EXPECT_EQ(p.at("mirror_label"), "mirror " + std::to_string(static_cast<int>(ti)) + "\u00b0");
      // The title is placed, not measured (plot_verify.py draw_panel): above the mirror label,
      // which is above the panel. Measured at the script's 25 pt pad: 0.011 of the figure's
      // height between the label's top and the title's bottom on these inputs.
      const auto &title = p.at("title_box"), &mirror = p.at("mirror_label_box");
      EXPECT_FALSE(overlap(title, mirror)) << f.at("file");
      EXPECT_GE(title[1].get<double>(), mirror[3].get<double>()) << f.at("file");
      EXPECT_GE(mirror[1].get<double>(), p.at("axes_box")[3].get<double>()) << f.at("file");
    }
    // Every curve named once, the models with their factors (the CSV's norm_factor).
    const auto& labels = f.at("legend_labels");
    ASSERT_EQ(labels.size(), 3u);
    EXPECT_EQ(labels[0], "measured");
    EXPECT_NE(labels[1].get<std::string>().find("computed (ray trace), normalization \u00d7 2"),
              std::string::npos)
        << labels[1];
  }
  // The zero and the NaN: the log axis masks both, the linear one only the NaN; none elsewhere.
  const auto& p30 = figures[1].at("panels");
  EXPECT_EQ(p30[0].at("masked_points"), 1);  // normalized R
  EXPECT_EQ(p30[3].at("masked_points"), 2);  // absolute R
  for (int i : {1, 2, 4, 5}) EXPECT_EQ(p30[i].at("masked_points"), 0) << i;
  for (const auto& p : figures[0].at("panels")) EXPECT_EQ(p.at("masked_points"), 0);
}
