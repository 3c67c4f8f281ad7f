// A mistyped subcommand or option, run through the weft program, is answered with the nearest
// valid name (tools/did_you_mean.h), naming the typo alone; and --quiet keeps stderr empty.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_run.h"
#include "did_you_mean.h"
#include "test_util.h"

namespace fs = std::filesystem;
using weft::cli::edit_distance;
using weft::cli::nearest_name;
using weft::testing::CliRun;
using weft::testing::fresh_test_dir;

namespace {

using weft::testing::run_weft_cli_in;

const std::string kScene = std::string(WEFT_SOURCE_DIR) + "/scenes/examples/lambert-plane.json";

// A parse error: CLI11's exit code for arguments it did not expect, and every one of 'parts' in
// stderr.
void expect_typo(const CliRun& r, std::initializer_list<std::string> parts) {
  EXPECT_EQ(r.exit_code, 109) << r.err;  // CLI::ExitCodes::ExtrasError
  EXPECT_EQ(r.err.rfind("weft: error: ", 0), 0u) << r.err;
  for (const auto& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << p << "\n" << r.err;
}

}  // namespace

TEST(EditDistance, CountsInsertionsDeletionsChangesAndSwaps) {
  EXPECT_EQ(edit_distance("render", "render"), 0u);
  EXPECT_EQ(edit_distance("rendr", "render"), 1u);     // one insertion
  EXPECT_EQ(edit_distance("renderr", "render"), 1u);   // one deletion
  EXPECT_EQ(edit_distance("randor", "render"), 2u);    // two changes
  EXPECT_EQ(edit_distance("preveiw", "preview"), 1u);  // one swap of neighbours
  EXPECT_EQ(edit_distance("", "weave"), 5u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);  // the textbook Levenshtein example
}

TEST(EditDistance, NearestNameOnlyWhenCloseEnough) {
  const std::vector<std::string> names = {"render", "weave", "verify", "sweep"};
  EXPECT_EQ(nearest_name("rendr", names), "render");
  EXPECT_EQ(nearest_name("veryfi", names), "verify");  // 6 letters: 2 off allowed
  EXPECT_EQ(nearest_name("wave", names), "weave");
  EXPECT_EQ(nearest_name("bake", names), "");  // 3 off 'weave': no guess
  EXPECT_EQ(nearest_name("x", names), "");
}

TEST(CliTypos, UnknownSubcommandSuggestsTheNearest) {
  const fs::path dir = fresh_test_dir();
  expect_typo(run_weft_cli_in("rendr", dir), {"unknown command 'rendr'", "did you mean 'render'?"});
  // A subcommand of a group.
  expect_typo(run_weft_cli_in("bake fibr red-cotton -o t.exr", dir),
              {"unknown command 'fibr' for 'weft bake'", "did you mean 'fiber'?"});
  // Nothing near: no guess.
  const CliRun far = run_weft_cli_in("zzzzzz", dir);
  expect_typo(far, {"unknown command 'zzzzzz'"});
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

TEST(CliTypos, UnknownFlagIsNamedAloneWithTheNearest) {
  const fs::path dir = fresh_test_dir();
  // The typo's value takes the scene's place: CLI11 listed the scene file as unexpected too.
  const CliRun r = run_weft_cli_in("render --preveiw p.png '" + kScene + "' -o out.exr", dir);
  expect_typo(r, {"unknown option '--preveiw' for 'weft render'", "did you mean '--preview'?"});
  EXPECT_EQ(r.err.find("lambert-plane.json"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("p.png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
  // A typo with '=' and one that leaves a required option unset.
  expect_typo(run_weft_cli_in("verify --qualty=draft -o v", dir),
              {"unknown option '--qualty'", "did you mean '--quality'?"});
  expect_typo(run_weft_cli_in("render '" + kScene + "' --ouptut out.exr", dir),
              {"unknown option '--ouptut'", "did you mean '--output'?"});
  // A global option before the subcommand.
  expect_typo(run_weft_cli_in("--max-memroy-gb 3 medium red-cotton", dir),
              {"unknown option '--max-memroy-gb'", "did you mean '--max-memory-gb'?"});
}

TEST(CliTypos, QuietRenderPrintsNothingOnStderr) {
  const fs::path dir = fresh_test_dir();
  // The bundled plane (a parallel light and an environment) at the smallest settings.
  const CliRun r =
      run_weft_cli_in("render '" + kScene +
                          "' -o out.exr -D render.width=8 -D render.height=8 -D render.spp=1 "
                          "--quiet",
                      dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(fs::exists(dir / "out.exr"));
  // Without --quiet the lights are described (so the check above could fail).
  const CliRun loud = run_weft_cli_in(
      "render '" + kScene + "' -o out2.exr -D render.width=8 -D render.height=8 -D render.spp=1",
      dir);
  EXPECT_EQ(loud.exit_code, 0) << loud.err;
  EXPECT_NE(loud.err.find("weft: light: "), std::string::npos) << loud.err;
}
