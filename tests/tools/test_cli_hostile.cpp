// Hostile inputs at the command line: for each command with outputs, an output that is one of the
// files the run reads at any depth (scene -> material -> table -> weave; part -> job -> fiber
// table; suite -> fabric -> measurement), named directly, through a symbolic link or through a
// hard link, is refused before any work (exit 2, the error names the output and the input, the
// input byte for byte as before); and what was once accepted without a word (a suite file's bad
// fabric, a table scaled by 1e30, an empty reference, parts of files edited since, an exposure
// with nothing to expose, a failed Slurm submission's scripts) is an error or a warning.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "cli_run.h"
#include "test_util.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_table.h"

namespace fs = std::filesystem;
using weft::testing::CliRun;
using weft::testing::fresh_test_dir;
using weft::testing::kExamples;
using weft::testing::run_weft_cli_in;
using weft::testing::slurp;

namespace {

const std::string kHostileSource = WEFT_SOURCE_DIR;

// 'args' with every "OUT" replaced by 'out'.
std::string hostile_with_output(std::string args, const std::string& out) {
  for (size_t at = args.find("OUT"); at != std::string::npos; at = args.find("OUT", at))
    args.replace(at, 3, out), at += out.size();
  return args;
}

// The run of 'args' with OUT as 'input' itself, as a symbolic link to it and as a hard link to it:
// each refused, exit 2, the error naming the output and 'input', 'input' unchanged.
void expect_refused_every_way(const fs::path& dir, const std::string& args,
                              const std::string& input) {
  const std::string before = slurp(dir / input);
  const std::string sym = "sym-" + fs::path(input).filename().string();
  const std::string hard = "hard-" + fs::path(input).filename().string();
  fs::remove(dir / sym);
  fs::remove(dir / hard);
  fs::create_symlink(fs::path(input).filename(), dir / sym);
  fs::create_hard_link(dir / input, dir / hard);
  for (const std::string& out : {input, sym, hard}) {
    const std::string line = hostile_with_output(args, out);
    const CliRun r = run_weft_cli_in(line, dir);
    EXPECT_EQ(r.exit_code, 2) << line << "\n" << r.err;
    EXPECT_NE(r.err.find("weft: error: "), std::string::npos) << line << "\n" << r.err;
    EXPECT_NE(r.err.find(out + ": "), std::string::npos) << line << "\n" << r.err;
    EXPECT_NE(r.err.find(input + "'"), std::string::npos) << line << "\n" << r.err;
    EXPECT_NE(r.err.find("refusing"), std::string::npos) << line << "\n" << r.err;
    EXPECT_EQ(slurp(dir / input), before) << input << " changed by: " << line;
  }
  fs::remove(dir / sym);
  fs::remove(dir / hard);
}

// A table of 'value' everywhere (1/sr), R = 2, RGB, of 'kind'.
void write_constant_table(const fs::path& path, double value, const std::string& kind) {
  auto t = weft::TabulatedBsdfTable::from_function(
      2, 3,
      [value](const weft::Vec3&, const weft::Vec3&, std::span<double> v) {
        v[0] = v[1] = v[2] = value;
      },
      1, 1);
  t.kind = kind;
  t.write_exr(path);
}

// A folder with the bundled plane as a fabric_table (fabric.exr) with a weave table (w.exr),
// the scene s.json with render and sweep settings of a few pixels.
fs::path hostile_woven_scene() {
  const fs::path dir = fresh_test_dir();
  write_constant_table(dir / "fabric.exr", 0.1, "fabric");
  weft::WeaveTable weave;
  weave.resolution = 1;
  weave.positions_u = weave.positions_v = 2;
  weave.repeat_u_m = weave.repeat_v_m = 0.5;
  weave.modulation = std::vector<float>(4 * 2 * 2 * 3, 1.0f);
  weave.write_exr(dir / "w.exr");
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  std::ofstream(dir / "s.json") << R"({"gltf": "lambert-plane.gltf",
    "materials": {"plane": {"type": "fabric_table",
                            "params": {"file": "fabric.exr", "weave": "w.exr"}}},
    "lights": [{"type": "parallel", "irradiance": 1.0, "zenith_deg": 30}],
    "camera": {"type": "orthographic", "frame_object": "plane", "zenith_deg": 0},
    "render": {"width": 4, "height": 4, "spp": 1, "max_depth": 2, "seed": 1},
    "sweep": {"sample": "plane", "light_zenith_deg": 30, "view_zenith_deg": [0, 10],
              "width": 4, "height": 4, "spp": 1}})";
  return dir;
}

}  // namespace

// scene -> material -> its weave table: render and sweep once replaced w.exr, exit 0.
TEST(CliHostile, RenderAndSweepRefuseTheWeaveTheirMaterialNames) {
  const fs::path dir = hostile_woven_scene();
  expect_refused_every_way(dir, "render s.json -o OUT --quiet", "w.exr");
  expect_refused_every_way(dir, "sweep s.json -o OUT --quiet", "w.exr");
  // The table and the glTF at the same depths.
  expect_refused_every_way(dir, "render s.json -o OUT --quiet", "fabric.exr");
  expect_refused_every_way(dir, "render s.json -o out.exr --preview OUT --quiet",
                           "lambert-plane.gltf");
  expect_refused_every_way(dir, "sweep s.json -o OUT --quiet", "s.json");
}

// part -> job -> fiber table: a fabric part records the fiber table by checksum only, so a merge
// once replaced it (-o and --weave-out). Then a part whose recorded input changed since.
TEST(CliHostile, MergeOfFabricPartsRefusesTheFiberTableAndNamesAChangedOne) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(
      run_weft_cli_in(
          "bake fiber red-cotton --photons 2000 --resolution 3 --bands rgb --quiet -o fiber.exr",
          dir)
          .exit_code,
      0);
  for (const char* k : {"0", "1"}) {
    const CliRun r = run_weft_cli_in(
        std::string("bake fabric --fiber fiber.exr --method raytrace --detail fiber -R 2 ") +
            "--samples 400 --quiet --shard " + k + "/2 -o p" + k + ".part",
        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  expect_refused_every_way(dir, "merge p0.part p1.part -o OUT", "fiber.exr");
  expect_refused_every_way(dir, "merge p0.part p1.part -o out.exr --weave-out OUT", "fiber.exr");
  expect_refused_every_way(dir, "merge p0.part p1.part -o OUT", "p0.part");
  // The fiber table edited since the parts: refused, naming the part, the file and "changed".
  std::ofstream(dir / "fiber.exr", std::ios::app) << "edited";
  const CliRun r = run_weft_cli_in("merge p0.part p1.part -o out.exr", dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("p0.part: field 'inputs'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fiber.exr (checksum"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("changed since"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

// Sweep parts of a scene edited after they were computed were merged as if it were the same.
TEST(CliHostile, MergeRefusesSweepPartsOfASceneEditedSince) {
  const fs::path dir = hostile_woven_scene();
  for (const char* k : {"0", "1"})
    ASSERT_EQ(run_weft_cli_in(
                  std::string("sweep s.json --shard ") + k + "/2 -o p" + k + ".part --quiet", dir)
                  .exit_code,
              0);
  ASSERT_EQ(run_weft_cli_in("merge p0.part p1.part -o before.csv", dir).exit_code, 0);
  std::string scene = slurp(dir / "s.json");
  scene.replace(scene.find("\"irradiance\": 1.0"), 17, "\"irradiance\": 2.0");
  std::ofstream(dir / "s.json") << scene;
  const CliRun r = run_weft_cli_in("merge p0.part p1.part -o after.csv", dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("s.json (checksum"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "after.csv"));
}

// --suite-file is a suite run with or without --suite, and every fabric of it is checked before
// the first runs: a bad pattern in the second fabric is named at once, no report folder made.
TEST(CliHostile, SuiteFileIsValidatedWholeBeforeAnyFabricRuns) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kHostileSource + "/materials/data/measured/merl-white-fabric/inplane.csv",
                dir / "m.csv");
  std::ofstream(dir / "mine.json") << R"({"title": "t", "fabrics": [
    {"name": "good", "measured": "m.csv", "fiber": "white-cotton", "known": "k"},
    {"name": "bad", "measured": "m.csv", "fiber": "white-cotton", "pattern": "twill:x",
     "known": "k"}]})";
  for (const std::string suite : {"", "--suite "}) {
    const CliRun r = run_weft_cli_in(
        "verify --quiet --quality draft " + suite + "--suite-file mine.json -o out", dir);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("mine.json: field 'fabrics[1]': 'bad'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("pattern"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out")) << suite;
  }
  const CliRun empty = run_weft_cli_in("verify --quiet --suite-file '' -o out", dir);
  EXPECT_EQ(empty.exit_code, 2) << empty.err;
  EXPECT_NE(empty.err.find("--suite-file"), std::string::npos) << empty.err;
  // suite -> fabric -> measurement, at every depth.
  expect_refused_every_way(dir, "verify --quiet --quality draft --suite-file mine.json -o OUT",
                           "m.csv");
}

// A table scaled by 1e30 returns 1e30 times the light: exported with a warning naming the table;
// a plausible one (0.1/sr: albedo 0.1 pi, docs/fiber-bsdf.md) without.
TEST(CliHostile, ExportWarnsOfATableReturningMoreLightThanArrives) {
  const fs::path dir = fresh_test_dir();
  write_constant_table(dir / "huge.exr", 1e30, "fabric");
  write_constant_table(dir / "fine.exr", 0.1, "fabric");
  const CliRun huge = run_weft_cli_in("export huge.exr -o huge.bsdf", dir);
  EXPECT_EQ(huge.exit_code, 0) << huge.err;
  EXPECT_NE(huge.err.find("weft: warning: huge.exr: the table returns up to"), std::string::npos)
      << huge.err;
  EXPECT_NE(huge.err.find("check the table's scale"), std::string::npos) << huge.err;
  const CliRun fine = run_weft_cli_in("export fine.exr -o fine.bsdf", dir);
  EXPECT_EQ(fine.exit_code, 0) << fine.err;
  EXPECT_EQ(fine.err.find("warning"), std::string::npos) << fine.err;
  // An output is refused by its extension before the guard, so the table as an output comes only
  // through a link of an exported format's name.
  const std::string before = slurp(dir / "fine.exr");
  fs::create_symlink("fine.exr", dir / "sym.bsdf");
  fs::create_hard_link(dir / "fine.exr", dir / "hard.bsdf");
  for (const std::string out : {"sym.bsdf", "hard.bsdf"}) {
    const CliRun r = run_weft_cli_in("export fine.exr -o " + out, dir);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(out + ": field '--output': is also the table 'fine.exr'"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(slurp(dir / "fine.exr"), before) << out;
  }
}

// An all-zero reference compared as identical (rel_rms 0): now an error naming it.
TEST(CliHostile, CompareRefusesAReferenceOfNoLight) {
  const fs::path dir = fresh_test_dir();
  write_constant_table(dir / "zero.exr", 0.0, "fabric");
  write_constant_table(dir / "b.exr", 0.1, "fabric");
  const CliRun r = run_weft_cli_in("compare zero.exr b.exr", dir);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("zero.exr: field 'values': the reference table holds no light"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(run_weft_cli_in("compare b.exr zero.exr", dir).exit_code, 0);
  expect_refused_every_way(dir, "compare b.exr zero.exr --csv OUT", "zero.exr");
}

// A reference with light on one side only (an opaque cloth: nothing in transmission) had its
// empty side reported as rel_rms 0, a perfect match, whatever B held there: now undefined, with
// B's own light there.
TEST(CliHostile, CompareCallsASideWithoutReferenceLightUndefined) {
  const fs::path dir = fresh_test_dir();
  auto opaque = weft::TabulatedBsdfTable::from_function(
      2, 3,
      [](const weft::Vec3& wo, const weft::Vec3& wi, std::span<double> v) {
        v[0] = v[1] = v[2] = wo.z * wi.z > 0 ? 0.1 : 0.0;
      },
      1, 1);
  opaque.kind = "fabric";
  opaque.write_exr(dir / "opaque.exr");
  write_constant_table(dir / "b.exr", 0.1, "fabric");
  const CliRun text = run_weft_cli_in("compare opaque.exr b.exr", dir);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("reflection    rel_rms 0.0000"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("transmission  undefined: the reference is zero on this side; B's RMS f "
                          "there 0.1 "),
            std::string::npos)
      << text.out;
  const CliRun json = run_weft_cli_in("compare opaque.exr b.exr --json", dir);
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_TRUE(j["transmission"]["rel_rms"].is_null()) << json.out;
  EXPECT_TRUE(j["transmission"]["max_rel"].is_null()) << json.out;
  EXPECT_TRUE(j["transmission"]["reference_zero"].get<bool>());
  EXPECT_NEAR(j["transmission"]["abs_rms"].get<double>(), 0.1, 1e-6);
  EXPECT_FALSE(j["reflection"]["reference_zero"].get<bool>());
  EXPECT_NEAR(j["reflection"]["rel_rms"].get<double>(), 0.0, 1e-6);
  EXPECT_GT(j["overall"]["rel_rms"].get<double>(), 0.5);  // B's transmission counts there
}

// --exposure only scales a PNG: with an EXR and no preview it did nothing, silently.
TEST(CliHostile, ExposureWithNothingToExposeIsAWarning) {
  const fs::path dir = hostile_woven_scene();
  const CliRun exr = run_weft_cli_in("render s.json -o out.exr --exposure 2 --quiet", dir);
  EXPECT_EQ(exr.exit_code, 0) << exr.err;
  EXPECT_NE(exr.err.find("weft: warning: --exposure does nothing here"), std::string::npos)
      << exr.err;
  const CliRun png =
      run_weft_cli_in("render s.json -o out2.exr --preview p.png --exposure 2 --quiet", dir);
  EXPECT_EQ(png.exit_code, 0) << png.err;
  EXPECT_EQ(png.err.find("warning"), std::string::npos) << png.err;
}

// A failed submission left OUTPUT.slurm/array.sh and merge.sh behind: now removed, and said.
TEST(CliHostile, SlurmRemovesItsScriptsWhenTheSubmissionFails) {
  const fs::path dir = fresh_test_dir();
  fs::create_directory(dir / "bin");
  std::ofstream(dir / "bin" / "sbatch") << "#!/bin/sh\necho 'sbatch: error: no partition' >&2\n"
                                           "echo 'no partition'\nexit 1\n";
  fs::permissions(dir / "bin" / "sbatch", fs::perms::owner_all);
  fs::copy_file(kHostileSource + "/fiber/presets/red-cotton.json", dir / "spec.json");
  const std::string cmd =
      "slurm --shards 2 bake fiber spec.json --resolution 2 --photons 20 --bands rgb -o f.exr";
  const CliRun r = run_weft_cli_in(cmd, dir, "PATH=\"$PWD/bin:$PATH\" ");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("submission failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("removed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("array.sh"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "f.exr.slurm")) << r.err;
  // A script folder that was there before stays, without the scripts.
  fs::create_directory(dir / "f.exr.slurm");
  const CliRun again = run_weft_cli_in(cmd, dir, "PATH=\"$PWD/bin:$PATH\" ");
  EXPECT_EQ(again.exit_code, 2) << again.err;
  EXPECT_TRUE(fs::is_directory(dir / "f.exr.slurm"));
  EXPECT_TRUE(fs::is_empty(dir / "f.exr.slurm")) << again.err;
}
