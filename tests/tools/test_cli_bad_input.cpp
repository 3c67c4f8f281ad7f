// Bad input and the memory and work budget: each case a hostile user tried, run
// through the weft program. Every one ends with a clear error naming the file or option and the
// field, a non-zero exit, and no output written.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::fresh_test_dir;
using weft::testing::slurp;

namespace {

using weft::testing::CliRun;

using weft::testing::run_weft_cli_in;

// 'text' with the first 'from' replaced by 'to' (which must be there).
std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.substr(0, at) + to + text.substr(at + from.size());
}

using weft::testing::write_file;

using weft::testing::kExamples;
const std::string kPlane = (kExamples / "lambert-plane.json").string();

// Expects a weft::Error: exit 2, every one of 'parts' in the message, and no file 'output'.
void expect_error(const CliRun& r, std::initializer_list<const char*> parts,
                  const fs::path& output) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // The error is the last line (a render logs its lights before it starts).
  std::string last = r.err;
  while (!last.empty() && last.back() == '\n') last.pop_back();
  last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
  EXPECT_EQ(last.rfind("weft: error: ", 0), 0u) << r.err;
  for (const char* p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << p << "\n" << r.err;
  EXPECT_FALSE(fs::exists(output)) << output;
}

}  // namespace

TEST(CliBadInput, NegativeOrOctalSeedIsRefused) {
  const fs::path dir = fresh_test_dir();
  // CLI11 read "-5" as 2^64 - 5 and "010" as 8, and the render ran.
  for (const char* seed : {"-5", "010", "1e3", "18446744073709551616"}) {
    const CliRun r =
        run_weft_cli_in("render '" + kPlane + "' -o out.exr --spp 1 --seed " + seed, dir);
    EXPECT_NE(r.exit_code, 0) << seed;
    EXPECT_NE(r.err.find("seed"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
  const CliRun bake = run_weft_cli_in("bake fiber red-cotton -o t.exr --seed -1", dir);
  EXPECT_NE(bake.exit_code, 0);
  EXPECT_NE(bake.err.find("seed"), std::string::npos) << bake.err;
}

TEST(CliBadInput, TableWrittenAsPngIsRefusedBeforeTheWork) {
  const fs::path dir = fresh_test_dir();
  expect_error(run_weft_cli_in("table bake lambert -R 2 -o table.png", dir), {"table.png", ".exr"},
               dir / "table.png");
  // Refused before the bake: 10^9 photons per band would otherwise run for hours first.
  expect_error(run_weft_cli_in("bake fiber red-cotton --photons 1000000000 -o table.png", dir),
               {"table.png", "--output", "must end in .exr"}, dir / "table.png");
}

TEST(CliBadInput, SweepViewListWithAStrayCommaOrTooFineAStepIsRefused) {
  const fs::path dir = fresh_test_dir();
  for (const char* views : {"0,10,", "0,,10", ",0"})
    expect_error(run_weft_cli_in("sweep '" + kPlane + "' -o s.csv --view-zenith-deg " + views, dir),
                 {"--view-zenith-deg", "stray comma"}, dir / "s.csv");
  // A step of 1e-7 asked for 8e8 views and died of std::bad_alloc.
  expect_error(run_weft_cli_in("sweep '" + kPlane + "' -o s.csv --view-zenith-deg 0:80:1e-7", dir),
               {"--view-zenith-deg", "8e+08 values, more than 100000"}, dir / "s.csv");
  // The same in a scene's sweep section names the JSON field.
  std::ifstream in(kPlane);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string scene = ss.str();
  const std::string step = "\"step\": 10";
  scene = replaced(scene, step, "\"step\": 1e-6");
  write_file(dir / "plane.json", scene);
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  expect_error(run_weft_cli_in("sweep plane.json -o s.csv", dir),
               {"plane.json", "sweep.view_zenith_deg.step", "more than 100000"}, dir / "s.csv");
}

TEST(CliBadInput, HugeNumberAndDeepNestingInASceneAreClearErrors) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  // Was "internal error" (nlohmann's out_of_range escaped).
  write_file(
      dir / "big.json",
      R"({"gltf": "lambert-plane.gltf", "lights": [{"type": "parallel", "irradiance": 1e400}]})");
  expect_error(run_weft_cli_in("render big.json -o out.exr", dir),
               {"big.json: field 'lights[0].irradiance': number 1e400 is out of range"},
               dir / "out.exr");
  // Was a segfault (unbounded recursion).
  write_file(dir / "deep.json", std::string(100000, '['));
  expect_error(run_weft_cli_in("render deep.json -o out.exr", dir),
               {"deep.json", "nested deeper than 128"}, dir / "out.exr");
}

TEST(CliBadInput, ExtremeFiberSpecsAreRefusedNamingTheField) {
  const fs::path dir = fresh_test_dir();
  const std::string base = R"({"name": "x", "fiber_radius_um": 6,
    "roughness": {"distribution": "ggx", "alpha": 0.2}, "host": {"n": HOST},
    "species": [SPECIES]})";
  auto spec = [&](const std::string& host, const std::string& species) {
    return replaced(replaced(base, "HOST", host), "SPECIES", species);
  };
  const std::string voids = R"({"name": "v", "n": 1.0, "k": 0, "volume_fraction": 0.001,
    "size": {"distribution": "lognormal", "median_radius_um": MEDIAN, "sigma": 0.3}})";
  auto with_median = [&](const std::string& m) { return replaced(voids, "MEDIAN", m); };
  // Each of these ran for hours without a word.
  write_file(dir / "median.json", spec("1.5", with_median("1e4")));
  expect_error(run_weft_cli_in("bake fiber median.json -o t.exr", dir),
               {"median.json", "species[0].size.median_radius_um", "half the fiber radius"},
               dir / "t.exr");
  write_file(dir / "host.json", spec("1e6", with_median("0.2")));
  expect_error(run_weft_cli_in("bake fiber host.json -o t.exr", dir),
               {"host.json", "host.n", "[1, 3]"}, dir / "t.exr");
  std::string many;
  for (int i = 0; i < 1000; ++i) {
    if (i) many += ",";
    many += with_median("0.2");
  }
  write_file(dir / "species.json", spec("1.5", many));
  expect_error(run_weft_cli_in("bake fiber species.json -o t.exr", dir),
               {"species.json", "'species'", "1000 species, more than 16"}, dir / "t.exr");
}

TEST(CliBadInput, LongBakesNeedConfirmation) {
  const fs::path dir = fresh_test_dir();
  // 1e12 photons per band: 33e12 photons at >= 0.5 us each is years on any machine here.
  const CliRun r = run_weft_cli_in("bake fiber red-cotton --photons 1000000000000 -o t.exr", dir);
  expect_error(r, {"--photons", "would take at least", "--yes-long"}, dir / "t.exr");
  // The bound follows the options (fiber_table_bake.h): 2.1 us per photon with the defaults'
  // next-event estimation and four surface samples, 0.5 us with plain exits.
  EXPECT_NE(r.err.find("2.1 us per photon per core at least"), std::string::npos) << r.err;
  const CliRun plain = run_weft_cli_in(
      "bake fiber red-cotton --photons 1000000000000 --estimator plain -o t.exr", dir);
  expect_error(plain, {"--photons", "0.5 us per photon per core at least"}, dir / "t.exr");
  // --yes-long passes that check (after the subcommand too); the memory budget then refuses (at
  // its floor of 0.05 GB, cli_util.h kMinMemoryGb, a bake at resolution 16 needs 178 MB).
  expect_error(
      run_weft_cli_in("bake fiber red-cotton --photons 1000000000000 --resolution 16 -o t.exr "
                      "--yes-long --max-memory-gb 0.05",
                      dir),
      {"--resolution", "needs about", "allowed by --max-memory-gb"}, dir / "t.exr");
}

// Renders, sweeps and ray-traced fabric tables estimate their time before starting, from a lower
// bound on the rate (render_settings.h kMinSecondsPerPathSample: 0.05 us per path sample per core;
// fabric_raytrace.h kMinSecondsPerFabricParticle: 0.25 us per particle per core), and refuse
// above an hour without --yes-long, naming the option and the rate.
TEST(CliBadInput, LongRendersSweepsAndRayTracesNeedConfirmation) {
  const fs::path dir = fresh_test_dir();
  // 4096^2 pixels x 10^6 spp x 0.05 us = 8.4e5 core-seconds: over an hour on up to 233 cores.
  expect_error(
      run_weft_cli_in("render " + kPlane + " --width 4096 --height 4096 --spp 1000000 -o t.exr",
                      dir),
      {"lambert-plane.json", "spp", "would take at least", "us per path sample", "--yes-long"},
      dir / "t.exr");
  // 15 views, each with its white reference, of 4096^2 pixels at 10^6 spp.
  expect_error(
      run_weft_cli_in("sweep " + kPlane + " --spp 1000000 --resolution 4096 -o t.csv", dir),
      {"lambert-plane.json", "spp", "a sweep of 15 views", "would take at least", "--yes-long"},
      dir / "t.csv");
  // 128 incident bins x 2^36 particles x 0.25 us: 2.2e6 core-seconds. Refused before the fiber
  // table is baked, so no bake cache appears either.
  expect_error(
      run_weft_cli_in("bake fabric --method raytrace -R 8 --samples 68719476736 -o t.exr", dir),
      {"--samples", "128 incident bins", "would take at least", "us per particle", "--yes-long"},
      dir / "t.exr");
  EXPECT_FALSE(fs::exists(dir / ".weft-cache"));
}

TEST(CliBadInput, WeaveTableOptionsAreNamedBeforeAnyWork) {
  // bake fabric --weave-out and its options (docs/fabric-bsdf.md, "The weave table"): refused by
  // name before the fiber table is baked, so no bake cache appears and no output is written.
  const fs::path dir = fresh_test_dir();
  const std::string bake = "bake fabric -R 4 -o t.exr ";
  const std::string raytrace = bake + "--method raytrace ";
  struct Case {
    std::string args;
    std::vector<const char*> parts;
  };
  for (const Case& c : std::vector<Case>{
           {bake + "--weave-out w.exr", {"--weave-out", "--method raytrace"}},
           {bake + "--weave-positions 4", {"--weave-positions", "--method raytrace"}},
           {raytrace + "--weave-positions 4", {"--weave-positions", "--weave-out"}},
           {raytrace + "--weave-resolution 2", {"--weave-resolution", "--weave-out"}},
           {raytrace + "--weave-out w.png", {"w.png", "--weave-out", ".exr"}},
           {raytrace + "--weave-out w.exr --weave-positions 0", {"--weave-positions", "[1, 64]"}},
           {raytrace + "--weave-out w.exr --weave-positions 65", {"--weave-positions", "'65'"}},
           {raytrace + "--weave-out w.exr --weave-positions 8x", {"--weave-positions", "'8x'"}},
           {raytrace + "--weave-out w.exr --weave-positions 2.5", {"--weave-positions"}},
           {raytrace + "--weave-out w.exr --weave-positions nanx4", {"--weave-positions"}},
           {raytrace + "--weave-out w.exr --weave-resolution 5", {"--weave-resolution", "4"}},
           {raytrace + "--weave-out w.exr --weave-resolution 0", {"--weave-resolution"}},
           {raytrace + "--weave-out t.exr", {"t.exr", "--weave-out"}},
       }) {
    const CliRun r = run_weft_cli_in(c.args, dir);
    EXPECT_NE(r.exit_code, 0) << c.args;
    for (const char* p : c.parts)
      EXPECT_NE(r.err.find(p), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir / "t.exr")) << c.args;
    EXPECT_FALSE(fs::exists(dir / "w.exr")) << c.args;
  }
  EXPECT_FALSE(fs::exists(dir / ".weft-cache"));
}

TEST(CliBadInput, MemoryBudgetRefusesBeforeAllocating) {
  const fs::path dir = fresh_test_dir();
  // A bake at R = 32 holds 33 bands of 2048^2 doubles twice: 2.3 GB even for one photon (the
  // measured peak of `weft bake fiber red-cotton --resolution 32 --photons 1 --bands rgb` was
  // 2.34 GB resident).
  expect_error(
      run_weft_cli_in("--max-memory-gb 1 bake fiber red-cotton --resolution 32 --photons 1 "
                      "--bands rgb -o t.exr",
                      dir),
      {"--resolution", "a bake at resolution 32 needs about 2.3 GB"}, dir / "t.exr");
  // A 16384^2 render with a mask: 68 bytes a pixel (the image, and the mask's counts, sums and
  // squares), 18.3 GB.
  expect_error(
      run_weft_cli_in("render '" + kPlane +
                          "' --width 16384 --height 16384 --mask m.exr --mask-object plane "
                          "-o out.exr --max-memory-gb 4",
                      dir),
      {"lambert-plane.json", "width x height", "with a mask needs about 18.3 GB"}, dir / "out.exr");
  EXPECT_FALSE(fs::exists(dir / "m.exr"));
}

TEST(CliBadInput, OutOfMemoryIsAClearErrorNotACrash) {
  const fs::path dir = fresh_test_dir();
  // The budget raised past what a 3 GB address space allows: the allocation fails, and main()
  // turns std::bad_alloc into exit code 2 with a message.
  const CliRun r =
      run_weft_cli_in("render '" + kPlane +
                          "' --width 16384 --height 16384 --mask m.exr --mask-object plane "
                          "-o out.exr --max-memory-gb 100 --quiet",
                      dir, "ulimit -v 3000000 && ");
  expect_error(r, {"out of memory"}, dir / "out.exr");
}

TEST(CliBadInput, ExrAttributeClaimingMoreThanTheFileIsRefusedBeforeReading) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 -o t.exr --quiet", dir).exit_code, 0);
  // Make the "units" string attribute claim 1.9 GB (OpenEXR allocated that before its error).
  std::string bytes = slurp(dir / "t.exr");
  ASSERT_LT(bytes.size(), 4096u);
  const std::string key = std::string("units") + '\0' + "string" + '\0';
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const uint32_t claim = 1900000000;
  for (int i = 0; i < 4; ++i) bytes[at + key.size() + i] = static_cast<char>(claim >> (8 * i));
  std::ofstream(dir / "bad.exr", std::ios::binary) << bytes;
  // Under a 1 GB address space the old reader died of std::bad_alloc; now it never asks.
  const CliRun r = run_weft_cli_in("table info bad.exr", dir, "ulimit -v 1000000 && ");
  expect_error(r, {"bad.exr", "field 'units'", "claims 1900000000 bytes"}, dir / "none");
}

// Found by fuzz_table_exr: a small table whose header says R = 32 (a 2048 x 2048 data window) had
// its pixel buffer allocated (50 MB in RGB, 553 MB spectral) before the short file failed to
// fill it, 10 s and 1.5 GB per input.
TEST(CliBadInput, ExrTableClaimingMorePixelsThanTheFileHoldsIsRefused) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 -o t.exr --quiet", dir).exit_code, 0);
  std::string bytes = slurp(dir / "t.exr");
  auto set_int = [&](const std::string& key, size_t offset, int32_t v) {
    const size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    for (int i = 0; i < 4; ++i)
      bytes[at + key.size() + 4 + offset + i] = static_cast<char>(uint32_t(v) >> (8 * i));
  };
  set_int(std::string("resolution") + '\0' + "int" + '\0', 0, 32);
  set_int(std::string("dataWindow") + '\0' + "box2i" + '\0', 8, 2047);   // max.x
  set_int(std::string("dataWindow") + '\0' + "box2i" + '\0', 12, 2047);  // max.y
  bytes += std::string(4096, '\0');  // room for the line offsets of 2048 lines
  std::ofstream(dir / "big.exr", std::ios::binary) << bytes;
  expect_error(run_weft_cli_in("table info big.exr", dir),
               {"big.exr", "field 'resolution'", "50331648 bytes of pixels", "can hold"},
               dir / "none");
}

// weft slurm writes batch scripts that run on a cluster: no value of the user's may add a line to
// them (a newline in --time wrote an #SBATCH line of the user's choosing), Slurm's values are
// checked against its syntax, and the wrapped command is checked by the same parser and checks
// as running it, before any script is written (no OUTPUT.slurm folder is left).
TEST(CliBadInput, SlurmRefusesValuesThatWouldChangeItsScripts) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kPlane, dir / "plane.json");
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  const std::string sweep = " sweep plane.json -o s.csv";
  struct Case {
    std::string options;
    const char* option;  // named in the error
  };
  for (const Case& c : std::vector<Case>{
           {"--time '1:00:00\n#SBATCH --mem=1'", "--time"},
           {"--time 'one hour'", "--time"},
           {"--time 1:00:00:00", "--time"},
           {"--partition 'cpu gpu'", "--partition"},
           {"--partition 'cpu\n#SBATCH --x'", "--partition"},
           {"--account 'a;b'", "--account"},
       }) {
    for (const char* dry : {"", " --dry-run"}) {
      const std::string args = std::string("slurm --shards 2") + dry + " " + c.options + sweep;
      const CliRun r = run_weft_cli_in(args, dir);
      expect_error(r, {c.option}, dir / "s.csv.slurm");
      EXPECT_EQ(r.out.find("#SBATCH"), std::string::npos) << r.out;
    }
  }
  // A newline in the wrapped command's output path, in any of its arguments.
  expect_error(run_weft_cli_in("slurm --shards 2 sweep plane.json -o 's\n.csv'", dir), {"'-o'"},
               dir / "s\n.csv.slurm");
  expect_error(run_weft_cli_in("slurm --shards 2 sweep plane.json --sample 'a\nb' -o s.csv", dir),
               {"--sample", "control character"}, dir / "s.csv.slurm");
  // Valid values go into the scripts as given (Slurm's time formats, a partition list).
  const CliRun ok = run_weft_cli_in(
      "slurm --shards 2 --dry-run --time 2-12 --partition cpu,long --account lab_1" + sweep, dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  for (const char* line :
       {"#SBATCH --time=2-12\n", "#SBATCH --partition=cpu,long\n", "#SBATCH --account=lab_1\n"})
    EXPECT_NE(ok.out.find(line), std::string::npos) << line << ok.out;
  EXPECT_FALSE(fs::exists(dir / "s.csv.slurm"));
  // More shards than the sweep's 16 units (15 views and the normal-incidence reference): the
  // check runs the last shard, which has work, and writes no part of its own.
  const CliRun many = run_weft_cli_in(std::string("slurm --shards 40 --dry-run") + sweep, dir);
  ASSERT_EQ(many.exit_code, 0) << many.err;
  EXPECT_EQ(many.out.find("views "), std::string::npos) << many.out;
  EXPECT_FALSE(fs::exists(dir / "s.csv.slurm"));
  EXPECT_FALSE(fs::exists(dir / "s.csv"));
}

TEST(CliBadInput, SlurmChecksTheWrappedCommandBeforeWritingScripts) {
  const fs::path dir = fresh_test_dir();
  fs::copy_file(kPlane, dir / "plane.json");
  fs::copy_file(kExamples / "lambert-plane.gltf", dir / "lambert-plane.gltf");
  // Refused by the wrapped command's own parser, its own checks and the output guard.
  expect_error(run_weft_cli_in("slurm --shards 2 bake fiber red-cotton --photons -5 -o t.exr", dir),
               {"--photons"}, dir / "t.exr.slurm");
  expect_error(run_weft_cli_in("slurm --shards 2 bake fiber nonesuch -o t.exr", dir), {"nonesuch"},
               dir / "t.exr.slurm");
  // A summation cannot be sharded: only the ray trace can.
  expect_error(run_weft_cli_in("slurm --shards 2 bake fabric -R 2 -o t.exr", dir),
               {"--method raytrace"}, dir / "t.exr.slurm");
  expect_error(run_weft_cli_in("slurm --shards 2 sweep plane.json -o lambert-plane.gltf", dir),
               {"lambert-plane.gltf", "refusing to overwrite"}, dir / "lambert-plane.gltf.slurm");
  expect_error(run_weft_cli_in("slurm --shards 2 sweep plane.json --spp 0 -o s.csv", dir),
               {"--spp"}, dir / "s.csv.slurm");
  // Work that a shard would refuse without --yes-long.
  expect_error(run_weft_cli_in(
                   "slurm --shards 2 bake fiber red-cotton --photons 1000000000000 -o t.exr", dir),
               {"--photons", "--yes-long"}, dir / "t.exr.slurm");
  // The scene's files are untouched and nothing was written beside them.
  EXPECT_EQ(slurp(dir / "plane.json"), slurp(kPlane));
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir))
    files += e.path().filename() != "stdout" && e.path().filename() != "stderr";
  EXPECT_EQ(files, 2u);
}

// Numbers that were accepted and then misread: NaN passed CLI11's Range checks (every comparison
// with NaN is false) and disabled the memory budget or the time limit, an empty --camera read as
// not given, 0 raytrace samples as the default and 2^32 + 1 summation samples wrapped to 1. Each
// is refused naming the option, before any work (no output).
TEST(CliBadInput, NonFiniteEmptyAndWrappingOptionValuesAreRefused) {
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(run_weft_cli_in("table bake lambert -R 2 --spp 1 -o a.exr --quiet", dir).exit_code, 0);
  const std::string render = "render '" + kPlane + "' -o out.exr --quiet ";
  const std::string sweep = "sweep '" + kPlane + "' -o out.exr --quiet ";
  struct Case {
    std::string args;
    const char* option;
  };
  for (const Case& c : std::vector<Case>{
           {render + "--time-limit nan", "--time-limit"},
           {render + "--time-limit inf", "--time-limit"},
           {render + "--exposure nan", "--exposure"},
           {render + "--camera ''", "--camera"},
           {render + "--preview ''", "--preview"},
           {std::string("--max-memory-gb nan ") + render, "--max-memory-gb"},
           {std::string("--max-memory-gb 0.001 ") + render, "--max-memory-gb"},
           {render + "--max-memory-gb inf", "--max-memory-gb"},
           {sweep + "--light-zenith-deg nan", "--light-zenith-deg"},
           {sweep + "--irradiance nan", "--irradiance"},
           {sweep + "--view-azimuth-deg nan", "--view-azimuth-deg"},
           {sweep + "--sample ''", "--sample"},
           {"compare a.exr a.exr --significant nan --csv out.exr", "--significant"},
           {"bake fabric --method raytrace -R 2 --samples 0 -o out.exr", "--samples"},
           {"bake fabric -R 2 --samples 4294967297 -o out.exr", "--samples"},
           {"bake fabric -R 2 --samples 0 -o out.exr", "--samples"},
           {"bench bake --target nan", "--target"},
           {"bench render --repeats 0", "--repeats"},
           {"bench render --repeats 1001", "--repeats"},
           {"bench sheen --fiber f.exr --reference-light bogus", "--reference-light"},
           {"bench sheen --fiber f.exr --reference-light narrow --band nan", "--band"},
           {"bench sheen --fiber f.exr --reference-light narrow --nee 65", "--nee"},
           {"bench sheen --fiber f.exr --narrow-reference r.json", "--narrow-reference"},
       }) {
    const CliRun r = run_weft_cli_in(c.args, dir);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.err.find(c.option), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr")) << c.args;
  }
  // In range the same options still run (the floor of the budget is 0.05 GB).
  EXPECT_EQ(run_weft_cli_in(
                "--max-memory-gb 0.05 table bake lambert -R 2 --spp 1 -o out.exr --quiet", dir)
                .exit_code,
            0);
}

namespace {

// What is in 'dir' besides the run's stdout and stderr and the inputs 'kept'.
std::vector<std::string> left_behind(const fs::path& dir, const std::vector<std::string>& kept) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name != "stdout" && name != "stderr" &&
        std::find(kept.begin(), kept.end(), name) == kept.end())
      out.push_back(name);
  }
  return out;
}

}  // namespace

// A measured table of a million incidences (26 MB) made `weft verify` run for minutes and abort
// with std::bad_alloc; one past the limit of measured.h (180 incidences) is refused at once,
// naming the file and the row, before any staging folder or bake cache exists.
TEST(CliBadInput, HugeOrDegenerateMeasuredTableIsRefusedBeforeAnyWork) {
  const fs::path dir = fresh_test_dir();
  std::string table = "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n";
  for (int i = 0; i <= 180; ++i) table += std::to_string(i * 0.25) + ",0,0.1,0.1,0.1\n";
  write_file(dir / "m.csv", table);
  expect_error(run_weft_cli_in("verify --measured m.csv --quality draft -o rep", dir),
               {"m.csv: field 'line 182 theta_i_deg'", "more than 180 incidences"}, dir / "rep");
  EXPECT_EQ(slurp(dir / "m.csv"), table);
  EXPECT_EQ(left_behind(dir, {"m.csv"}), std::vector<std::string>{});
  write_file(dir / "m.csv",
             "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n"
             "0,0,0.1,1e300,0.1\n");
  expect_error(run_weft_cli_in("verify --measured m.csv --quality draft -o rep", dir),
               {"m.csv: field 'line 2 nbrdf_beta_G'", "absurd"}, dir / "rep");
  EXPECT_EQ(left_behind(dir, {"m.csv"}), std::vector<std::string>{});
}

// A scene's fiber_table named by a spec is baked on first use (bake_cache.h); 10^12 photons per
// band ran with no estimate. Now the bake on first use takes the checks of `weft bake fiber`
// (33 bands x 10^12 photons at >= 0.5 us each: years): refused without --yes-long, naming the
// scene and the material's photons field, before the bake cache exists. The same for a sweep.
TEST(CliBadInput, BakeOnFirstUseNeedsConfirmationLikeADirectBake) {
  const fs::path dir = fresh_test_dir();
  const std::string scene = replaced(
      slurp(kPlane), R"({"type": "lambert", "params": {"reflectance": 0.5}})",
      R"({"type": "fiber_table", "params": {"spec": "red-cotton", "photons": 1000000000000}})");
  write_file(dir / "scene.json",
             replaced(scene, "lambert-plane.gltf", (kExamples / "lambert-plane.gltf").string()));
  for (const std::string output : {"t.exr", "t.csv"}) {
    const std::string command = (output == "t.exr" ? "render" : "sweep");
    expect_error(run_weft_cli_in(command + " scene.json -o " + output, dir),
                 {"scene.json", "materials.plane.params.photons", "1000000000000 photons per band",
                  "would take at least", "--yes-long"},
                 dir / output);
    EXPECT_FALSE(fs::exists(dir / ".weft-cache")) << command;
  }
}

// A summation-visible table at R = 32 with 4096 direction pairs per cell pair: 2048^2 x 4096 =
// 1.7e10 pairs at >= 5 us each (fabric_summation.h kMinSecondsPerVisiblePair; measured 26 us)
// ran with no estimate; now it is refused before the fiber table is baked.
TEST(CliBadInput, LongSummationNeedsConfirmation) {
  const fs::path dir = fresh_test_dir();
  expect_error(
      run_weft_cli_in("bake fabric --method summation-visible -R 32 --samples 4096 -o t.exr", dir),
      {"--samples", "a summation-visible of 4194304 cell pairs x 4096 direction pairs",
       "would take at least", "5 us per direction pair", "--yes-long"},
      dir / "t.exr");
  EXPECT_FALSE(fs::exists(dir / ".weft-cache"));
}

namespace {

// The scene of a ray trace or summation-visible is estimated before anything is built
// (fabric_scene_bytes, docs/weave.md "Large drafts"): over the budget it is refused naming the
// draft and the estimate, before the fiber table is baked. The bundled 84 x 100 draft's yarn
// tubes need about 2.1 GB at 16 x 16 and 0.28 GB at the coarsest 4 x 4 (docs/PERFORMANCE.md), so
// 0.2 GB fits no tessellation; at fiber detail it needs about 5.5 GB (the fibers it will hold:
// docs/weave.md).
TEST(CliBadInput, FabricSceneOverTheMemoryBudgetIsRefusedNamingTheDraft) {
  const fs::path dir = fresh_test_dir();
  const std::string draft = std::string(WEFT_SOURCE_DIR) + "/scenes/data/wif/8452.wif";
  for (const char* method : {"raytrace", "summation-visible"})
    expect_error(run_weft_cli_in(std::string("--max-memory-gb 0.2 bake fabric --method ") + method +
                                     " -R 1 --wif '" + draft + "' -o t.exr",
                                 dir),
                 {"8452.wif", "field '--detail'", "the scene at yarn detail", "needs about",
                  "allowed by --max-memory-gb"},
                 dir / "t.exr");
  expect_error(
      run_weft_cli_in(
          "--max-memory-gb 3 bake fabric --method raytrace --detail fiber -R 1 --wif '" + draft +
              "' -o t.exr",
          dir),
      {"8452.wif", "the scene at fiber detail", "4.03476e+06 curve points", "needs about 5.5 GB"},
      dir / "t.exr");
  EXPECT_FALSE(fs::exists(dir / ".weft-cache"));
}

}  // namespace
