#include "weft/core/child_process.h"

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <thread>

#include "weft/core/error.h"

namespace weft {
namespace {

constexpr auto kPollPeriod = std::chrono::milliseconds(20);
// After SIGTERM, how long the group has to end before SIGKILL: matplotlib's workers exit at
// once on SIGTERM, and a stop must stay well within a second.
constexpr auto kTermGrace = std::chrono::milliseconds(500);

// The child reaped: true with its status once it ended (or is gone: waitpid failed).
bool reaped(pid_t pid, int& status, bool block) {
  for (;;) {
    const pid_t r = waitpid(pid, &status, block ? 0 : WNOHANG);
    if (r == pid) return true;
    if (r == 0) return false;
    if (errno != EINTR) {  // no such child: nothing left to wait for
      status = -1;
      return true;
    }
  }
}

// SIGTERM to the child's group, SIGKILL after the grace if the child is still there; reaped.
void end_group(pid_t pid, int& status) {
  kill(-pid, SIGTERM);
  const auto give_up = std::chrono::steady_clock::now() + kTermGrace;
  while (std::chrono::steady_clock::now() < give_up) {
    if (reaped(pid, status, false)) {
      kill(-pid, SIGKILL);  // what the child left running in its group
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(-pid, SIGKILL);
  reaped(pid, status, true);
}

}  // namespace

ChildOutcome run_child_process(const std::vector<std::string>& argv,
                               const std::function<bool()>& keep_going) {
  if (argv.empty()) throw Error("", "argv", "no program to run");
  // Everything the child needs is made before fork: between fork and exec a child of a threaded
  // process may only make async-signal-safe calls.
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw Error(argv[0], "", std::string("cannot start: ") + std::strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);
    // A handler does not survive exec, but an ignored signal would: the child starts with the
    // default action whatever the caller had.
    std::signal(SIGINT, SIG_DFL);
    execv(args[0], args.data());
    _exit(127);
  }
  setpgid(pid, pid);  // also here, so that the group exists before any kill below
  ChildOutcome out;
  int status = 0;
  while (!reaped(pid, status, false)) {
    if (!keep_going()) {
      end_group(pid, status);
      out.stopped = true;
      return out;
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
  if (status != -1 && WIFEXITED(status)) out.exit_code = WEXITSTATUS(status);
  return out;
}

}  // namespace weft
