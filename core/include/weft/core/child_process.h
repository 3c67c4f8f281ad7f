#pragma once
// Another program run to its end, or stopped when the caller's work is stopped. system() would
// do the first, but it ignores SIGINT in the caller while the child runs: a Ctrl-C sent to weft
// alone (not to its process group) was lost until the child ended, and so was any other stop.
#include <functional>
#include <string>
#include <vector>

namespace weft {

struct ChildOutcome {
  bool stopped = false;  // keep_going said stop: the child's process group was ended
  int exit_code = -1;    // the child's exit status; -1 when a signal ended it or it never ran
};

// Runs argv[0] (an absolute path; no shell, no PATH search) with argv[1..] in a process group of
// its own, inheriting stdin, stdout and stderr, and waits for it, asking keep_going() every
// 20 ms. Once it says stop, the whole group (the child and whatever it started) gets SIGTERM, and
// SIGKILL half a second later if it is still there; the call returns once the child is reaped.
// weft::Error naming argv[0] when the process cannot be started; exit code 127 when the program
// could not be executed.
ChildOutcome run_child_process(const std::vector<std::string>& argv,
                               const std::function<bool()>& keep_going);

}  // namespace weft
