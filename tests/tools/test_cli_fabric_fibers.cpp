// `weft bake fabric` with per-yarn fibers (--warp-fiber, --weft-fiber) and a WIF draft's
// --thread-colours (fabric/fabric_fibers.h): one fiber given per yarn is the single-fiber run
// byte for byte, two differ and are named in the summary, the draft's colours become one baked
// fiber each, and every misuse is refused by the option's name before any work.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.h"
#include "test_util.h"
#include "weft/materials/bsdf_table.h"

namespace fs = std::filesystem;
using weft::testing::CliRun;
using weft::testing::fresh_test_dir;
using weft::testing::slurp;

namespace {

const fs::path kWifDir = fs::path(WEFT_SOURCE_DIR) / "scenes" / "data" / "wif";

using weft::testing::run_weft_cli_in;

// Expects 'args -o out' refused (exit 2) with 'part' in the error and nothing written.
void expect_refused(const std::string& args, const std::string& part, const fs::path& dir) {
  const fs::path out = dir / "refused.exr";
  const CliRun r = run_weft_cli_in(args + " -o '" + out.string() + "'", dir);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(part), std::string::npos) << args << "\n" << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A small fiber table of a preset (RGB, R = 3), baked into dir.
fs::path small_fiber(const std::string& preset, const fs::path& dir) {
  const fs::path out = dir / (preset + ".exr");
  const CliRun r = run_weft_cli_in("bake fiber " + preset +
                                       " --photons 2000 --resolution 3 --bands rgb --quiet -o '" +
                                       out.string() + "'",
                                   dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return out;
}

// A clear fibre (no inclusions): its bake on first use is quick.
const char* kClearSpec = R"({"name": "clear", "fiber_radius_um": 6,
  "roughness": {"distribution": "beckmann", "alpha": 0.3}, "host": {"n": 1.5}, "species": []})";

}  // namespace

TEST(CliFabricFibers, OneFiberPerYarnIsTheSingleFiberRunAndTwoAreNamed) {
  const fs::path dir = fresh_test_dir();
  const fs::path red = small_fiber("red-cotton", dir), white = small_fiber("white-cotton", dir);
  const std::string base =
      "bake fabric --method raytrace --detail yarn -R 2 --samples 300 --quiet --json";
  const fs::path single = dir / "single.exr", same = dir / "same.exr", two = dir / "two.exr";
  ASSERT_EQ(
      run_weft_cli_in(base + " --fiber '" + red.string() + "' -o '" + single.string() + "'", dir)
          .exit_code,
      0);
  ASSERT_EQ(run_weft_cli_in(base + " --warp-fiber '" + red.string() + "' --weft-fiber '" +
                                red.string() + "' -o '" + same.string() + "'",
                            dir)
                .exit_code,
            0);
  EXPECT_EQ(slurp(single), slurp(same));  // byte for byte, metadata included
  const CliRun r = run_weft_cli_in(base + " --fiber '" + red.string() + "' --weft-fiber '" +
                                       white.string() + "' -o '" + two.string() + "'",
                                   dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("fiber_tables").size(), 2u);
  EXPECT_EQ(j.at("fiber_tables")[0].at("name"), "warp");
  EXPECT_EQ(j.at("fiber_tables")[1].at("name"), "weft");
  EXPECT_EQ(j.at("fiber_tables")[1].at("spec"), "white-cotton");
  const auto t = weft::TabulatedBsdfTable::read_exr(two);
  EXPECT_NE(t.metadata.at("fiber_tables").find("weft: "), std::string::npos);
  EXPECT_NE(t.values, weft::TabulatedBsdfTable::read_exr(single).values);
  // The summation takes one fiber: the same one per yarn is that fiber, two are refused.
  const std::string sum = "bake fabric --method summation -R 2 --samples 2 --quiet";
  const fs::path summed = dir / "summed.exr";
  EXPECT_EQ(run_weft_cli_in(sum + " --warp-fiber '" + red.string() + "' --weft-fiber '" +
                                red.string() + "' -o '" + summed.string() + "'",
                            dir)
                .exit_code,
            0);
  expect_refused(sum + " --fiber '" + red.string() + "' --warp-fiber '" + white.string() + "'",
                 "--warp-fiber", dir);
}

TEST(CliFabricFibers, ThreadColoursBakeOneFiberPerColourOfTheDraft) {
  // The project's red/white twill (scenes/data/wif/README.md): a clear fibre dyed red for the
  // warp, the clear fibre itself for the white weft; the cloth is redder than the undyed one.
  const fs::path dir = fresh_test_dir();
  std::ofstream(dir / "clear.json") << kClearSpec;
  const std::string draft = (kWifDir / "red-white-twill.wif").string();
  const std::string base =
      "bake fabric --method raytrace --detail yarn -R 2 --samples 300 "
      "--quiet --json --fiber clear.json --wif '" +
      draft + "'";
  // The rule: this test is of the mapping of colours to yarns (the match is tested in
  // tests/fabric/test_fabric_colour.cpp).
  const CliRun r =
      run_weft_cli_in(base + " --thread-colours --thread-colour-method rule -o dyed.exr", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("fiber_tables").size(), 2u);
  // [COLOR TABLE] 1=200,30,30 (warps), 2=255,255,255 (wefts), warps first.
  EXPECT_EQ(j.at("fiber_tables")[0].at("name"), "#c81e1e");
  EXPECT_EQ(j.at("fiber_tables")[0].at("spec"), "clear #c81e1e");
  EXPECT_EQ(j.at("fiber_tables")[1].at("spec"), "clear");
  const CliRun plain = run_weft_cli_in(base + " -o plain.exr", dir);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto a = weft::TabulatedBsdfTable::read_exr(dir / "dyed.exr").total_albedo();
  const auto b = weft::TabulatedBsdfTable::read_exr(dir / "plain.exr").total_albedo();
  EXPECT_GT(a[0] / a[1], 1.1 * b[0] / b[1]);
}

TEST(CliFabricFibers, ThreadColourMisuseIsRefusedByName) {
  const fs::path dir = fresh_test_dir();
  const std::string twill = (kWifDir / "red-white-twill.wif").string();
  const std::string rt = "bake fabric --method raytrace -R 2 --samples 10 --quiet";
  // No draft; per-direction fibers as well; the summation.
  expect_refused(rt + " --thread-colours", "--thread-colours", dir);
  expect_refused(rt + " --wif '" + twill + "' --thread-colours --warp-fiber white-cotton",
                 "--thread-colours", dir);
  expect_refused("bake fabric --method summation -R 2 --wif '" + twill + "' --thread-colours",
                 "--thread-colours", dir);
  // The draft's colours dye a spec, not a table.
  const fs::path table = small_fiber("white-cotton", dir);
  expect_refused(rt + " --wif '" + twill + "' --thread-colours --fiber '" + table.string() + "'",
                 "--fiber", dir);
  // A draft without colours: the bundled 54235-plain.wif without its colour sections.
  std::string text = slurp(kWifDir / "54235-plain.wif");
  for (const char* section : {"[WARP COLORS]\n1=1\n2=1\n", "[WEFT COLORS]\n1=2\n2=2\n"}) {
    const auto at = text.find(section);
    ASSERT_NE(at, std::string::npos) << section;
    text.erase(at, std::string(section).size());
  }
  std::ofstream(dir / "grey.wif") << text;
  expect_refused(rt + " --wif grey.wif --thread-colours", "WARP COLORS", dir);
  // Nine colours, one more than the cap: a plain weave of nine warps, each its own red.
  std::string nine =
      "[WIF]\nVersion=1.1\n[WEAVING]\nShafts=2\nTreadles=2\n[WARP]\nThreads=9\n"
      "Units=Millimeters\nSpacing=0.2\nThickness=0.18\n[WEFT]\nThreads=2\n"
      "Units=Millimeters\nSpacing=0.2\nThickness=0.18\n[TIEUP]\n1=1\n2=2\n[TREADLING]\n"
      "1=1\n2=2\n[THREADING]\n";
  for (int i = 1; i <= 9; ++i) nine += std::to_string(i) + "=" + std::to_string(1 + i % 2) + "\n";
  nine += "[COLOR PALETTE]\nEntries=9\nRange=0,255\n[COLOR TABLE]\n";
  for (int i = 1; i <= 9; ++i) nine += std::to_string(i) + "=" + std::to_string(10 * i) + ",0,0\n";
  nine += "[WARP COLORS]\n";
  for (int i = 1; i <= 9; ++i) nine += std::to_string(i) + "=" + std::to_string(i) + "\n";
  std::ofstream(dir / "nine.wif") << nine;
  expect_refused(rt + " --wif nine.wif --thread-colours", "at most 8", dir);
  // Yarn detail: warps of two colours are one tube mesh.
  std::string two = slurp(kWifDir / "red-white-twill.wif");
  two.replace(two.find("[WARP COLORS]\n1=1\n2=1"), 21, "[WARP COLORS]\n1=1\n2=2");
  std::ofstream(dir / "two.wif") << two;
  expect_refused(rt + " --detail yarn --wif two.wif --thread-colours --fiber white-cotton",
                 "fiber detail", dir);
}
