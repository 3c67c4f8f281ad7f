#include "cli_util.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"

namespace weft::cli {
namespace {
std::atomic<bool> g_interrupted{false};  // set by the signal handler only
// Whether the work polls interrupted() (progress_bar was made). Until then no one reads the flag
// (a plan only reads and checks; a command without progress never polls): Ctrl-C ends the program
// at once. Outputs are written atomically, so none is left half-written either way.
std::atomic<bool> g_polled{false};

// Async-signal-safe: write() and _exit() only.
[[noreturn]] void exit_interrupted(const char* message, size_t size) {
  (void)!write(STDERR_FILENO, message, size);
  _exit(130);
}

extern "C" void on_sigint(int) {
  static constexpr char kBeforeWork[] = "\nweft: interrupted\n";
  // A step that does not poll (building a large sample or scene) can take minutes: a second
  // Ctrl-C does not wait for it.
  static constexpr char kAgain[] = "\nweft: interrupted again; stopped at once\n";
  if (!g_polled.load()) exit_interrupted(kBeforeWork, sizeof kBeforeWork - 1);
  if (g_interrupted.exchange(true)) exit_interrupted(kAgain, sizeof kAgain - 1);
}

}  // namespace

// SIGTERM as SIGINT: a batch scheduler's stop (Slurm's scancel or time limit, `timeout`) asks as
// politely as Ctrl-C, and killed at once weft left its plot script's process group running.
void install_interrupt_handler() {
  std::signal(SIGINT, on_sigint);
  std::signal(SIGTERM, on_sigint);
}
bool interrupted() {
  return g_interrupted.load();
}

std::function<bool()> polled_interrupt() {
  install_interrupt_handler();
  g_polled.store(true);
  return [] { return !g_interrupted.load(); };
}

ProgressCallback progress_bar(const RunLimits& limits, bool quiet) {
  work_starts(limits);
  install_interrupt_handler();
  g_polled.store(true);
  using Clock = std::chrono::steady_clock;
  struct State {
    Clock::time_point start = Clock::now();
    Clock::time_point last_draw{};
    std::string stage;
  };
  auto state = std::make_shared<State>();
  // A terminal gets one line redrawn in place; a log file or pipe gets plain lines, fewer of them,
  // so that a batch job's log is readable rather than one line of carriage returns.
  const bool terminal = isatty(fileno(stderr)) != 0;
  const auto period = terminal ? std::chrono::milliseconds(200) : std::chrono::milliseconds(10000);
  return [state, quiet, terminal, period](const ProgressUpdate& u) {
    if (!quiet) {
      const auto now = Clock::now();
      if (u.stage != state->stage) {
        state->stage = std::string(u.stage);
        state->start = now;
        state->last_draw = now;  // the first line comes one period into the stage
      }
      const bool finished = u.total > 0 && u.done >= u.total;
      if (finished || now - state->last_draw > period) {
        state->last_draw = now;
        const double elapsed = std::chrono::duration<double>(now - state->start).count();
        const std::string line = format_progress_line(u, elapsed);
        if (terminal)
          std::fprintf(stderr, "\r%-70s%s", line.c_str(), finished ? "\n" : "");
        else
          std::fprintf(stderr, "%s\n", line.c_str());
        std::fflush(stderr);
      }
    }
    return !g_interrupted.load();
  };
}

void report_scene_loaded(const SceneDescription& desc, bool quiet) {
  for (const auto& w : desc.warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  if (quiet) return;
  // What the lights are, in the renderer's units (glTF photometric values were converted).
  for (const auto& n : desc.notes) std::fprintf(stderr, "weft: %s\n", n.c_str());
  for (const auto& l : describe_lights(desc.lights))
    std::fprintf(stderr, "weft: light: %s\n", l.c_str());
}

int report_render_outcome(const RenderOutcome& r, const std::string& what) {
  if (r.cancelled) {
    std::fprintf(stderr, "\nweft: %s cancelled; nothing was written\n", what.c_str());
    return 130;
  }
  if (r.nonfinite_samples)
    std::fprintf(stderr, "weft: warning: %llu non-finite samples were dropped\n",
                 static_cast<unsigned long long>(r.nonfinite_samples));
  return 0;
}

RunLimits program_limits(double max_memory_gb, bool yes_long) {
  RunLimits l;
  l.max_memory_bytes = max_memory_gb * 1e9;
  l.yes_long = yes_long;
  l.announce = [](const std::string& line) { std::fprintf(stderr, "weft: %s\n", line.c_str()); };
  return l;
}

RunLimits quieted(RunLimits limits, bool quiet) {
  if (quiet) limits.announce = nullptr;
  return limits;
}

CLI::Validator seed_validator() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const bool digits = !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (s.size() > 1 && s[0] == '0'))
          return "a seed is a decimal integer in [0, 18446744073709551615], got '" + s + "'";
        errno = 0;
        std::strtoull(s.c_str(), nullptr, 10);
        if (errno == ERANGE) return "a seed must be below 2^64, got '" + s + "'";
        return "";
      },
      "SEED");
}

CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        const auto v = finite_number(s);
        if (!v || *v < lo || *v > hi)
          return "must be a finite number in [" + ParamReader::fmt(lo) + ", " +
                 ParamReader::fmt(hi) + "], got '" + s + "'";
        return "";
      },
      "NUMBER in [" + ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) + "]");
}

CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& s) -> std::string { return s.empty() ? "must not be empty" : ""; }, "");
}

}  // namespace weft::cli
