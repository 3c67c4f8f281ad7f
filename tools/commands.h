#pragma once
// Every subcommand registers itself here; main.cpp calls each add_* once.
#include "cli_util.h"

namespace weft::cli {

void add_slab_command(CLI::App& app, Commands& commands);
void add_spectrum_command(CLI::App& app, Commands& commands);
void add_bake_command(CLI::App& app, Commands& commands);
void add_bench_command(CLI::App& app, Commands& commands);
void add_mie_command(CLI::App& app, Commands& commands);
void add_medium_command(CLI::App& app, Commands& commands);
void add_table_command(CLI::App& app, Commands& commands);
void add_render_command(CLI::App& app, Commands& commands);
void add_sweep_command(CLI::App& app, Commands& commands);
void add_weave_command(CLI::App& app, Commands& commands);
void add_compare_command(CLI::App& app, Commands& commands);
// The "fabric" subcommand of the "bake" group (cmd_bake_fabric.cpp).
void add_bake_fabric_command(CLI::App& bake, Commands& commands);

// The subcommands of "bench" (cmd_bench.cpp makes the group).
void add_bench_bake_command(CLI::App& bench, Commands& commands);
void add_bench_render_command(CLI::App& bench, Commands& commands);

}  // namespace weft::cli
