// --quiet on the long commands, as a script meets it: nothing on stderr for a bundled case of
// each (progress lines and notes suppressed), where the same run without --quiet writes
// something there; errors are still printed. (verify --quiet: test_cli_verify.cpp, whose draft
// run is the costly one.)
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_run.h"
#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::CliRun;
using weft::testing::fresh_test_dir;
using weft::testing::run_weft_cli;

namespace {

using weft::testing::kExamples;

// Runs 'args' with and without --quiet: both succeed, the quiet run's stderr is empty and the
// other's is not; returns the quiet run.
CliRun expect_quiet(const std::string& args, const fs::path& dir) {
  const CliRun loud = run_weft_cli(args, dir);
  EXPECT_EQ(loud.exit_code, 0) << args << "\n" << loud.err;
  const CliRun quiet = run_weft_cli(args + " --quiet", dir);
  EXPECT_EQ(quiet.exit_code, 0) << args << "\n" << quiet.err;
  EXPECT_EQ(quiet.err, "") << args;
  EXPECT_NE(loud.err, "") << args << ": nothing to suppress, the case tests nothing";
  return quiet;
}

}  // namespace

TEST(CliQuiet, MediumAndBakes) {
  const fs::path dir = fresh_test_dir();
  expect_quiet("medium red-cotton", dir);
  const std::string fiber = (dir / "fiber.exr").string();
  expect_quiet("bake fiber red-cotton --photons 60 --resolution 2 --passes 2 -o '" + fiber + "'",
               dir);
  expect_quiet("bake fabric --method summation -R 4 --samples 2 --fiber '" + fiber + "' -o '" +
                   (dir / "fabric.exr").string() + "'",
               dir);
}

TEST(CliQuiet, Sweep) {
  const fs::path dir = fresh_test_dir();
  expect_quiet("sweep '" + kExamples.string() +
                   "/lambert-plane.json' --light-zenith-deg 30 --view-zenith-deg -30:30:30 "
                   "--spp 1 --resolution 8 -o '" +
                   (dir / "s.csv").string() + "'",
               dir);
}

TEST(CliQuiet, WeaveKeepsTheSummaryWithoutItsNotes) {
  const fs::path dir = fresh_test_dir();
  // Fibers of 12 um do not fit the default packing: the weave notes the packing it took.
  const std::string args =
      "weave --detail fiber --fiber-radius-um 12 -o '" + (dir / "w.glb").string() + "'";
  const CliRun loud = run_weft_cli(args, dir);
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  EXPECT_NE(loud.out.find("note: warp: the default packing"), std::string::npos) << loud.out;
  const CliRun quiet = run_weft_cli(args + " --quiet", dir);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(quiet.out.find("note:"), std::string::npos) << quiet.out;
  EXPECT_NE(quiet.out.find("fiber detail"), std::string::npos) << quiet.out;
  // An error is still printed.
  const CliRun bad = run_weft_cli("weave --quiet --packing 0.9 --detail fiber -o x.glb", dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("packing"), std::string::npos) << bad.err;
}
