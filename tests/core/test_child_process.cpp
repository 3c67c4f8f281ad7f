// run_child_process: a program run to its end gives its exit code; stopped, its whole process
// group (the child and what it started) is ended before the call returns.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "test_util.h"
#include "weft/core/child_process.h"
#include "weft/core/error.h"

namespace fs = std::filesystem;

// A named namespace: the unity build puts this file in one batch with others (ARCHITECTURE.md).
namespace weft::child_process_test {

bool always() {
  return true;
}

// Whether 'pid' is still a live process (a zombie no longer runs).
bool alive(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string id, name, state;
  return (in >> id >> name >> state) && state != "Z" && state != "X";
}

TEST(ChildProcess, RunsToItsEndAndGivesItsExitCode) {
  const ChildOutcome ok = run_child_process({"/bin/sh", "-c", "exit 0"}, always);
  EXPECT_FALSE(ok.stopped);
  EXPECT_EQ(ok.exit_code, 0);
  const ChildOutcome three = run_child_process({"/bin/sh", "-c", "exit 3"}, always);
  EXPECT_FALSE(three.stopped);
  EXPECT_EQ(three.exit_code, 3);
}

TEST(ChildProcess, ArgumentsGoAsTheyAreWithoutAShell) {
  // A quote or a dollar in an argument is the argument's own (system() went through the shell).
  const fs::path dir = weft::testing::fresh_test_dir();
  const std::string text = "it's $HOME; `x`";
  const ChildOutcome r = run_child_process(
      {"/bin/sh", "-c", "printf '%s' \"$1\" > \"$2\"", "sh", text, (dir / "out").string()}, always);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(weft::testing::slurp(dir / "out"), text);
}

TEST(ChildProcess, AProgramThatCannotRunExitsWith127) {
  const ChildOutcome r = run_child_process({"/nonexistent/program"}, always);
  EXPECT_FALSE(r.stopped);
  EXPECT_EQ(r.exit_code, 127);
  EXPECT_THROW(run_child_process({}, always), Error);
}

TEST(ChildProcess, StoppedItEndsTheChildAndWhatItStarted) {
  // The child starts a grandchild (as plot_verify.py starts its drawing processes) and waits; a
  // stop once the grandchild's pid is written ends both, the grandchild ignoring SIGTERM.
  const fs::path dir = weft::testing::fresh_test_dir();
  const fs::path pid_file = dir / "grandchild";
  int asked = 0;
  const ChildOutcome r = run_child_process(
      {"/bin/sh", "-c",
       "(trap '' TERM; sleep 600) & echo $! > \"$1.part\" && mv \"$1.part\" \"$1\"; wait", "sh",
       pid_file.string()},
      [&] {
        ++asked;
        return !fs::exists(pid_file);
      });
  EXPECT_TRUE(r.stopped);
  EXPECT_GT(asked, 0);
  const pid_t grandchild = std::stoi(weft::testing::slurp(pid_file));
  // The SIGKILL was sent before the call returned; its delivery and the reaping by init are not
  // instant, so wait for it (at most 10 s: this checks that it ends, not how fast).
  for (int i = 0; i < 500 && alive(grandchild); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(alive(grandchild));
}

}  // namespace weft::child_process_test
