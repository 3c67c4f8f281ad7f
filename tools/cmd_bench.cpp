// weft bench: the benchmark group; each of its subcommands lives in its own cmd_bench_*.cpp.
#include "commands.h"

namespace weft::cli {

void add_bench_command(CLI::App& app, Commands& commands) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks");
  bench->require_subcommand(1);
  add_bench_bake_command(*bench, commands);
  add_bench_render_command(*bench, commands);
  add_bench_flatten_command(*bench, commands);
  add_bench_sheen_command(*bench, commands);
}

}  // namespace weft::cli
