#pragma once
// Shared pieces of the command-line front end: the subcommand registry, the progress bar on
// stderr, and Ctrl-C handling that asks long work to stop cleanly.
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/progress.h"

namespace weft {
struct RenderOutcome;
struct SceneDescription;
struct SceneOverride;
}  // namespace weft

namespace weft::cli {

// A subcommand: its CLI11 app and what to run when it was chosen. run() returns the exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};
using Commands = std::vector<Command>;

// Progress on stderr (format_progress_line: percent, rate with its unit, ETA), silent when quiet:
// on a terminal one line redrawn in place, elsewhere (a log, a pipe) a plain line every 10 s and
// at the end of each stage. It returns false once the user
// pressed Ctrl-C, so the library stops at the next task boundary and keeps what it has.
ProgressCallback progress_bar(bool quiet);
// Installs the SIGINT handler used by progress_bar (idempotent).
void install_interrupt_handler();
bool interrupted();

// The scene description at 'path', its warnings printed on stderr (commands that render it).
SceneDescription load_scene_reporting_warnings(const std::string& path);
// Same with "-D key=value" overrides applied to the description (description.h).
SceneDescription load_scene_reporting_warnings(const std::string& path,
                                               const std::vector<SceneOverride>& overrides);
// The end of a render on stderr, alike for every command that renders: a cancelled run says that
// 'what' wrote nothing and gives exit code 130; dropped non-finite samples are a warning.
// Returns the exit code to stop with, or 0 to go on to the outputs.
int report_render_outcome(const RenderOutcome& r, const std::string& what);

// The finite number that is the whole of 'text', or nothing ("1.5x", "nan", "inf", "").
std::optional<double> finite_number(const std::string& text);

// Checks a command's output paths before any work: each names a file in an existing directory,
// no two name the same file and none names one of the inputs (compared by canonical path, so
// "./x" and "x" or a symbolic link are the same file). Inputs that are not files (a preset name)
// are ignored. weft::Error naming the output otherwise.
void validate_output_paths(const std::vector<std::string>& outputs,
                           const std::vector<std::string>& inputs);

// Parses "a:b:step" (inclusive) or a single value or "a,b,c" into a list of numbers.
std::vector<double> parse_range(const std::string& text, const std::string& option_name);

}  // namespace weft::cli
