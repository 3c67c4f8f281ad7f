#pragma once
// Every subcommand registers itself here; main.cpp calls each add_* once.
#include <memory>

#include "cli_util.h"
#include "weft/core/job_part.h"
#include "weft/exchange/export_report.h"

namespace weft::cli {

// What each cmd_*.cpp provides: adds its subcommand (and its runner) under 'parent'. One
// signature for all, so main.cpp can hold them in a list.
using AddCommand = void(CLI::App& parent, Commands& commands);

AddCommand add_slab_command, add_spectrum_command, add_bake_command, add_bench_command,
    add_mie_command, add_medium_command, add_table_command, add_render_command, add_sweep_command,
    add_weave_command, add_compare_command, add_merge_command, add_slurm_command, add_scene_command,
    add_export_command, add_view_command;

// The "fabric" subcommand of the "bake" group (cmd_bake_fabric.cpp).
AddCommand add_bake_fabric_command;
AddCommand add_verify_command;  // cmd_verify.cpp

// The subcommands of "bench" (cmd_bench.cpp makes the group).
AddCommand add_bench_bake_command, add_bench_render_command, add_bench_flatten_command,
    add_bench_sheen_command;

// The weft program: global options (--max-memory-gb, --yes-long) and every subcommand
// (program.cpp). main() parses and runs one; weft slurm parses the command it wraps with another.
struct Program {
  CLI::App app{"Weft: physically based fabric appearance pipeline and renderer", "weft"};
  Commands commands;
  double max_memory_gb = 0;  // 0: the memory available
  bool yes_long = false;
};
std::unique_ptr<Program> make_program();
// Runs, under the limits of the global options (program_limits), the subcommand the parse chose:
// its exit code. weft::Error and other exceptions propagate. With 'check_only_inputs' the run only
// checks (RunLimits::check_only: WorkWouldStart where the work would start) and collects there the
// inputs the command guards (weft slurm's check of the command it wraps).
int run_program(const Program& p,
                std::shared_ptr<std::vector<NamedPath>> check_only_inputs = nullptr);

// Each command's merge (in its cmd_*.cpp): writes 'output' from all units of its job and prints
// the command's summary. Returns the exit code.
int merge_fiber_bake(const JobPart& all, const std::string& output, bool json);
// weave_out: the weave table's file, given exactly when the parts carry a weave tally.
int merge_fabric_bake(const JobPart& all, const std::string& output, const std::string& weave_out,
                      bool json);
int merge_sweep(const JobPart& all, const std::string& output, bool json);
int merge_verify(const JobPart& all, const std::string& output, bool json);

// What an export or a page wrote (weft export, weft view): its summary, or the same as JSON.
int print_export_report(const ExportReport& r, const std::string& output, const std::string& table,
                        bool json);

}  // namespace weft::cli
