#pragma once
// Running the weft executable from the command-line tests: stdout and stderr go to files in the
// test's own folder, so stderr is not a terminal (progress comes as plain lines).
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "test_util.h"  // slurp

namespace weft::testing {

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

// Runs `weft ARGS` with stdout and stderr in dir/stdout and dir/stderr; 'prefix' goes before the
// command in the shell (an environment variable, a ulimit, a cd).
inline CliRun run_weft_cli(const std::string& args, const std::filesystem::path& dir,
                           const std::string& prefix = "") {
  const std::string cmd = prefix + "'" + std::string(WEFT_EXE) + "' " + args + " >'" +
                          (dir / "stdout").string() + "' 2>'" + (dir / "stderr").string() + "'";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(dir / "stdout");
  r.err = slurp(dir / "stderr");
  return r;
}

// The same run from inside 'dir': relative paths and the bake cache (./.weft-cache) are the
// test's own.
inline CliRun run_weft_cli_in(const std::string& args, const std::filesystem::path& dir,
                              const std::string& prefix = "") {
  return run_weft_cli(args, dir, "cd '" + dir.string() + "' && " + prefix);
}

}  // namespace weft::testing
