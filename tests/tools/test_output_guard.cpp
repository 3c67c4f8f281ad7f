// The output guard (core/output_guard.h validate_output_paths), command by command: an output that is a
// file the job reads (the path itself, a symbolic or a hard link to it, or a derived output such
// as render's OUT.albedo.exr) or a folder output that holds one is refused before any work: exit 2,
// a message naming both, the input's bytes unchanged and nothing left behind in the folder.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "cli_run.h"
#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::CliRun;
using weft::testing::fresh_test_dir;
using weft::testing::slurp;

namespace {

const std::string kSource = WEFT_SOURCE_DIR;
using weft::testing::kExamples;

using weft::testing::run_weft_cli_in;

// Every name under 'dir' but the run's stdout and stderr.
std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string n = fs::relative(e.path(), dir).string();
    if (n != "stdout" && n != "stderr") names.insert(n);
  }
  return names;
}

// Runs 'args' in 'dir' and expects the refusal: exit 2, the output and the input named in the
// error, 'input' byte for byte as before and no file added or removed in 'dir'.
void expect_refused(const fs::path& dir, const std::string& args, const std::string& output,
                    const std::string& input) {
  const std::string before = slurp(dir / input);
  const std::set<std::string> files = listing(dir);
  const CliRun r = run_weft_cli_in(args, dir);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find("weft: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(output + ": "), std::string::npos) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(input + "'"), std::string::npos) << args << "\n" << r.err;
  EXPECT_NE(r.err.find("refusing"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / input), before) << input << " changed by: " << args;
  EXPECT_EQ(listing(dir), files) << "files added or removed by: " << args;
}

// A folder with the lambert plane's glTF, a fiber table t.exr and a scene s.json whose plane is
// that fiber table.
fs::path scene_with_fiber_table() {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  EXPECT_EQ(run_weft_cli_in("table bake lambert -R 2 --spp 1 -o t.exr --quiet", dir).exit_code, 0);
  std::ofstream(dir / "s.json") << R"({"gltf": "lambert-plane.gltf",
    "materials": {"plane": {"type": "fiber_table", "params": {"file": "t.exr"}}},
    "lights": [{"type": "parallel", "irradiance": 1.0, "zenith_deg": 30}],
    "camera": {"type": "orthographic", "frame_object": "plane", "zenith_deg": 0},
    "render": {"width": 4, "height": 4, "spp": 1, "max_depth": 2, "seed": 1},
    "sweep": {"sample": "plane", "light_zenith_deg": 30, "view_zenith_deg": [0, 10],
              "width": 4, "height": 4, "spp": 1}})";
  return dir;
}

}  // namespace

TEST(OutputGuard, RenderRefusesEveryFileTheSceneReads) {
  const fs::path dir = scene_with_fiber_table();
  expect_refused(dir, "render s.json -o t.exr --quiet", "t.exr", "t.exr");
  // A derived output: the albedo pass of out.exr is out.albedo.exr.
  fs::copy_file(dir / "t.exr", dir / "out.albedo.exr");
  std::string scene = slurp(dir / "s.json");
  scene.replace(scene.find("\"t.exr\""), 7, "\"out.albedo.exr\"");
  std::ofstream(dir / "s2.json") << scene;
  expect_refused(dir, "render s2.json -o out.exr --aov albedo --quiet", "out.albedo.exr",
                 "out.albedo.exr");
  expect_refused(dir, "render s.json -o out.exr --preview lambert-plane.gltf --quiet",
                 "lambert-plane.gltf", "lambert-plane.gltf");
  // By identity: a symbolic link and a hard link to the table are the table.
  fs::create_symlink("t.exr", dir / "link.exr");
  expect_refused(dir, "render s.json -o link.exr --quiet", "link.exr", "t.exr");
  fs::create_hard_link(dir / "t.exr", dir / "hard.exr");
  expect_refused(dir, "render s.json -o hard.exr --quiet", "hard.exr", "t.exr");
}

TEST(OutputGuard, SweepAndMergeRefuseTheirInputs) {
  const fs::path dir = scene_with_fiber_table();
  expect_refused(dir, "sweep s.json -o lambert-plane.gltf --quiet", "lambert-plane.gltf",
                 "lambert-plane.gltf");
  expect_refused(dir, "sweep s.json -o t.exr --quiet", "t.exr", "t.exr");
  // A merge reads the parts and, through their job, every input the shards read.
  for (const char* k : {"0", "1"})
    ASSERT_EQ(run_weft_cli_in(
                  std::string("sweep s.json --shard ") + k + "/2 -o p" + k + ".part --quiet", dir)
                  .exit_code,
              0);
  expect_refused(dir, "merge p0.part p1.part -o t.exr", "t.exr", "t.exr");
  expect_refused(dir, "merge p0.part p1.part -o p1.part", "p1.part", "p1.part");
}

TEST(OutputGuard, BakesRefuseTheirSpecTableAndDraft) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kSource + "/fiber/presets/red-cotton.json", dir / "spec.json");
  fs::copy_file(kSource + "/scenes/data/wif/54235-plain.wif", dir / "d.wif");
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 --spp 1 -o t.exr --quiet", dir).exit_code, 0);
  expect_refused(dir, "bake fiber spec.json -o spec.json", "spec.json", "spec.json");
  expect_refused(dir, "bake fabric --fiber t.exr -R 2 -o t.exr --quiet", "t.exr", "t.exr");
  expect_refused(dir, "bake fabric --fiber t.exr -R 2 --wif d.wif -o d.wif --quiet", "d.wif",
                 "d.wif");
  // A merge of fiber-bake parts reads the spec file they name.
  for (const char* k : {"0", "1"})
    ASSERT_EQ(run_weft_cli_in(
                  std::string("bake fiber spec.json --resolution 2 --photons 20 --bands rgb ") +
                      "--shard " + k + "/2 -o f" + k + ".part --quiet",
                  dir)
                  .exit_code,
              0);
  expect_refused(dir, "merge f0.part f1.part -o spec.json", "spec.json", "spec.json");
}

TEST(OutputGuard, WeaveAndCompareRefuseTheirInputs) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kSource + "/scenes/data/wif/54235-plain.wif", dir / "d.wif");
  std::ofstream(dir / "sample.json") << R"({"wif": "d.wif"})";
  expect_refused(dir, "weave --wif d.wif -o d.wif", "d.wif", "d.wif");
  expect_refused(dir, "weave --sample sample.json -o sample.json", "sample.json", "sample.json");
  // The WIF the sample file names is read too.
  expect_refused(dir, "weave --sample sample.json -o d.wif", "d.wif", "d.wif");
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 --spp 1 -o a.exr --quiet", dir).exit_code, 0);
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 --spp 2 -o b.exr --quiet", dir).exit_code, 0);
  expect_refused(dir, "compare a.exr b.exr --csv a.exr", "a.exr", "a.exr");
  expect_refused(dir, "compare a.exr b.exr --plot b.exr", "b.exr", "b.exr");
  // table bake of a table material: the table its parameters name is an input.
  expect_refused(dir, "table bake fiber_table -R 2 --params '{\"file\": \"a.exr\"}' -o a.exr",
                 "a.exr", "a.exr");
}

TEST(OutputGuard, VerifyRefusesAReportFolderHoldingItsMeasurement) {
  const fs::path dir = fresh_test_dir();
  // An earlier report folder (replaced whole by a new run) where the user keeps the measurement.
  fs::create_directory(dir / "report");
  std::ofstream(dir / "report" / "metrics.json") << R"({"report": "weft verify"})";
  fs::copy_file(kSource + "/materials/data/measured/merl-white-fabric/inplane.csv",
                dir / "report" / "m.csv");
  expect_refused(dir, "verify --quiet --quality draft --measured report/m.csv -o report", "report",
                 "report/m.csv");
}

// The same for a suite: its output folder, an earlier suite's, holds the suite file and the
// measurement it names.
TEST(OutputGuard, VerifySuiteRefusesAnOutputFolderHoldingItsInputs) {
  const fs::path dir = fresh_test_dir();
  fs::create_directory(dir / "out");
  std::ofstream(dir / "out" / "suite.json") << R"({"report": "weft verify suite"})";
  fs::copy_file(kSource + "/materials/data/measured/merl-white-fabric/inplane.csv",
                dir / "out" / "m.csv");
  std::ofstream(dir / "out" / "mine.json") << R"({"title": "t", "fabrics": [{"name": "w",
    "measured": "m.csv", "fiber": "white-cotton", "known": "k"}]})";
  expect_refused(dir, "verify --quiet --quality draft --suite-file out/mine.json -o out", "out",
                 "out/mine.json");
}

// Concurrent `weft compare --plot` runs shared one temporary file name for their curves (15 of 20
// plots showed another run's curves). Each run's plot, drawn with others running at once, is
// byte for byte the plot it draws alone, and no temporary stays behind in TMPDIR.
TEST(OutputGuard, ConcurrentComparePlotsDrawTheirOwnCurves) {
  const fs::path dir = fresh_test_dir();
  fs::create_directory(dir / "tmp");
  for (const char* r : {"0.2", "0.4", "0.6", "0.8"})
    ASSERT_EQ(
        run_weft_cli_in(
            std::string("table bake lambert -R 2 --spp 1 --quiet --params '{\"reflectance\": ") +
                r + "}' -o t" + r + ".exr",
            dir)
            .exit_code,
        0);
  const std::vector<std::string> pairs = {"t0.2.exr t0.4.exr", "t0.4.exr t0.6.exr",
                                          "t0.6.exr t0.8.exr", "t0.2.exr t0.8.exr"};
  const std::string env = "export TMPDIR='" + (dir / "tmp").string() + "'; ";
  for (size_t i = 0; i < pairs.size(); ++i)
    ASSERT_EQ(
        run_weft_cli_in("compare " + pairs[i] + " --plot alone" + std::to_string(i) + ".png", dir)
            .exit_code,
        0);
  std::string together;
  for (size_t i = 0; i < pairs.size(); ++i)
    together += "'" + std::string(WEFT_EXE) + "' compare " + pairs[i] + " --plot together" +
                std::to_string(i) + ".png >/dev/null & ";
  ASSERT_EQ(std::system(("cd '" + dir.string() + "' && " + env + together + "wait").c_str()), 0);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::string n = std::to_string(i);
    const std::string alone = slurp(dir / ("alone" + n + ".png"));
    ASSERT_FALSE(alone.empty());
    EXPECT_EQ(slurp(dir / ("together" + n + ".png")), alone) << pairs[i];
    if (i) {
      EXPECT_NE(alone, slurp(dir / "alone0.png")) << "the pairs must plot differently";
    }
  }
  EXPECT_TRUE(fs::is_empty(dir / "tmp"));
}
