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
#include "weft/core/params.h"
#include "weft/core/progress.h"
#include "weft/fiber/bake_cache.h"

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
ProgressCallback progress_bar(bool quiet);  // throws WorkWouldStart when check_only
// Installs the SIGINT handler used by progress_bar (idempotent).
void install_interrupt_handler();
bool interrupted();

// The scene description at 'path' with "-D key=value" overrides applied (description.h), its
// warnings printed on stderr (commands that render it); unless 'quiet', its notes and lights too.
SceneDescription load_scene_reporting_warnings(const std::string& path,
                                               const std::vector<SceneOverride>& overrides,
                                               bool quiet);
// The end of a render on stderr, alike for every command that renders: a cancelled run says that
// 'what' wrote nothing and gives exit code 130; dropped non-finite samples are a warning.
// Returns the exit code to stop with, or 0 to go on to the outputs.
int report_render_outcome(const RenderOutcome& r, const std::string& what);

// The limits of one run of weft, from the global options (main.cpp): --max-memory-gb (default:
// the memory available when weft starts) and --yes-long (work estimated above kLongWorkSeconds).
struct RunLimits {
  double max_memory_bytes = 0;  // 0: available_memory_bytes()
  bool yes_long = false;
  // weft slurm's check of the command it wraps: every check the command makes, then progress_bar
  // throws WorkWouldStart where the work would start. The memory available here is not the
  // cluster's, so only an explicit --max-memory-gb is checked.
  bool check_only = false;
  // The command's --quiet: check_long_work announces no long work (errors are still thrown).
  bool quiet = false;
};
struct WorkWouldStart {};
RunLimits& run_limits();
// MemAvailable from /proc/meminfo (what can be allocated without swapping), else free pages.
double available_memory_bytes();
// The memory budget: --max-memory-gb, else the memory available; 0 (none) in weft slurm's check
// without an explicit --max-memory-gb.
double memory_budget_bytes();
// Error(file, field, ...) when an estimate of 'bytes' exceeds the memory budget: checked before
// allocating, so a run that cannot fit stops at once instead of dying of std::bad_alloc.
void check_memory(double bytes, const std::string& file, const std::string& field,
                  const std::string& what);
// Work estimated to take at least this long needs --yes-long; above a minute the estimate is
// printed on stderr before the work starts.
inline constexpr double kLongWorkSeconds = 3600;
inline constexpr double kAnnouncedWorkSeconds = 60;
// Before long work, from a lower bound of its time: 'units' of work at 'seconds_per_unit' per
// core on the cores 'threads' gives (0: all). Prints "weft: WHAT: at least T (BASIS)" on stderr
// above kAnnouncedWorkSeconds, and throws Error(file, field, ...) above kLongWorkSeconds unless
// --yes-long. 'rate' names the rate the bound assumes ("0.05 us per path sample per core"): the
// basis printed is it with the cores.
void check_long_work(double units, double seconds_per_unit, int threads, const std::string& file,
                     const std::string& field, const std::string& what, const std::string& rate);
// The checks before a fiber bake, the same for `weft bake fiber` and a bake on first use: its
// memory (check_memory, fiber_table_bake_bytes) and its time for 'bands' bands (check_long_work at
// kMinSecondsPerPhoton), naming the source's file and fields.
void check_fiber_bake(const FiberTableBakeOptions& options, uint64_t bands,
                      const FiberBakeSource& source);
// The time check before a fabric bake of 'method' (summation | summation-visible | raytrace), the
// same for `weft bake fabric` and the Python module: check_long_work at the method's least rate
// (fabric/) for a ray trace of 'bins_traced' incident bins x 'samples' particles, or a summation
// of every cell pair x 'samples' direction pairs (the method's default when not given).
void check_fabric_bake(const std::string& method, int resolution, uint64_t bins_traced,
                       std::optional<uint64_t> samples, int threads,
                       const std::string& samples_field);
// The fiber-table resolver of every command that renders a scene: fiber_table_resolver (bake on
// first use) with check_fiber_bake before a bake.
FiberTableResolver checked_fiber_table_resolver();
// The per-pixel buffers of a render: the image (3 floats), the sRGB preview (3 bytes) and a
// masked render's hit counts, sums and squares (3 + 3 doubles) and coverage (a float).
double render_bytes(int width, int height, bool preview, bool mask);
// "2.3 GB", "95 s", "41 min", "3.2 h", "2.1 days" for messages (times rounded up).
std::string format_bytes(double bytes);
std::string format_seconds(double seconds);

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

// THE output guard: every command checks its outputs here before any work. Each output names a
// file in an existing directory, no two outputs name the same file, and none is any file the job
// reads: compared by identity (same device and inode, so a symbolic or hard link to an input is
// that input), a not-yet-existing output by its resolved folder and name. An output inside an
// input folder (the bake cache) is refused too. 'folders' are outputs replaced whole (verify's
// report folder, weft slurm's script folder): refused when they hold any input. Inputs that are
// not files (a preset name) are ignored. weft::Error naming the output and the input otherwise.
void validate_output_paths(const std::vector<NamedPath>& outputs,
                           const std::vector<NamedPath>& inputs,
                           const std::vector<NamedPath>& folders = {});
// Every input validate_output_paths was given in this process, oldest first: weft slurm checks its
// scripts against the inputs of the command it wraps after checking that command (check_only).
const std::vector<NamedPath>& guarded_inputs();

// Every string in 'j' (values and keys, at any depth) that names an existing file or folder,
// named 'what' for the output guard: the files a part's job or a material's parameters name.
std::vector<NamedPath> json_named_files(const nlohmann::json& j, const std::string& what);

// Every file a render or sweep of the description reads: the description, its glTF files and
// buffers and environment maps, and what its materials name (tables, measured networks, fiber
// specs; a preset name is no file). Relative names resolve as registry.cpp and bake_cache.cpp
// resolve them.
std::vector<std::filesystem::path> scene_input_files(const std::string& scene,
                                                     const SceneDescription& d);
// The same named for the output guard, with the scene's fiber-table bake cache folder.
std::vector<NamedPath> scene_inputs(const std::string& scene, const SceneDescription& d);

// Parses "a:b:step" (inclusive) or a single value or "a,b,c" into a list of numbers; at most
// max_count of them (a range's count is checked before the list is built), no empty items.
inline constexpr size_t kMaxRangeCount = 100000;
std::vector<double> parse_range(const std::string& text, const std::string& option_name,
                                size_t max_count = kMaxRangeCount);

}  // namespace weft::cli
