#pragma once
// Shared pieces of the command-line front end: the subcommand registry, the progress bar on
// stderr, and Ctrl-C handling that asks long work to stop cleanly.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"
#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/fiber/bake_cache.h"

namespace weft {
struct RenderOutcome;
struct SceneDescription;
struct SceneOverride;
}  // namespace weft

namespace weft::cli {

// A subcommand: its CLI11 app and what to run when it was chosen, under the run's limits (weft
// slurm runs it check-only). run() returns the exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int(const RunLimits&)> run;
};
using Commands = std::vector<Command>;

// Progress on stderr (format_progress_line: percent, rate with its unit, ETA), silent when quiet:
// on a terminal one line redrawn in place, elsewhere (a log, a pipe) a plain line every 10 s and
// at the end of each stage. It returns false once the user pressed Ctrl-C, so the library stops
// at the next task boundary and keeps what it has. Made where the work starts: throws
// WorkWouldStart in a check-only run (work_starts).
ProgressCallback progress_bar(const RunLimits& limits, bool quiet);
// Installs the SIGINT handler, for SIGTERM too (idempotent; main does it first thing): until a
// progress_bar is
// made, Ctrl-C ends the program at once with exit code 130 (nothing has been written: a plan only
// reads and checks); after it, Ctrl-C sets interrupted() for the work to stop at its next poll,
// and a second Ctrl-C ends the program at once.
void install_interrupt_handler();
bool interrupted();
// From here on Ctrl-C sets interrupted(), as after progress_bar, for a command without progress
// whose step must clean up after itself (a child process to end: a plot script); the poll.
std::function<bool()> polled_interrupt();

// A scene description just loaded (commands that render it): its warnings on stderr; unless
// 'quiet', its notes and lights too.
void report_scene_loaded(const SceneDescription& desc, bool quiet);
// The end of a render on stderr, alike for every command that renders: a cancelled run says that
// 'what' wrote nothing and gives exit code 130; dropped non-finite samples are a warning.
// Returns the exit code to stop with, or 0 to go on to the outputs.
int report_render_outcome(const RenderOutcome& r, const std::string& what);

// The limits of one run of weft (core/run_limits.h) from the global options --max-memory-gb
// (default: the memory available when weft starts) and --yes-long; long work is announced on
// stderr.
RunLimits program_limits(double max_memory_gb, bool yes_long);
// The command's limits under its --quiet: no announcement of long work (errors are still thrown).
RunLimits quieted(RunLimits limits, bool quiet);

// A seed is a plain decimal number below 2^64: CLI11 would read "-5" as 2^64 - 5 and "010" as
// octal 8. main.cpp adds it to every --seed option.
CLI::Validator seed_validator();

// A number option in [lo, hi], read by finite_number (params.h): CLI11's Range lets "nan" through
// (every comparison with NaN is false), and "inf" past an open bound. Every floating-point option
// takes this check.
CLI::Validator finite_range(double lo, double hi);
// A string option given as "" (--camera '') is refused rather than read as not given.
CLI::Validator non_empty();
// The floor of --max-memory-gb: below it no command can run (the memory budget, RunLimits).
inline constexpr double kMinMemoryGb = 0.05;

}  // namespace weft::cli
