// weft: the command-line front end of the Weft fabric appearance pipeline.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>

#include "cli_util.h"
#include "commands.h"
#include "weft/core/error.h"

namespace {

// Every --seed of every subcommand takes only plain decimal seeds (cli::seed_validator).
void check_seeds(CLI::App& app) {
  for (CLI::Option* o : app.get_options())
    if (o->check_lname("seed")) o->check(weft::cli::seed_validator());
  for (CLI::App* sub : app.get_subcommands({})) check_seeds(*sub);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Weft: physically based fabric appearance pipeline and renderer", "weft"};
  app.set_version_flag("--version", WEFT_VERSION);
  app.require_subcommand(1);
  // The run's limits may follow the subcommand ("weft bake fiber ... --yes-long"): subcommands
  // made after this pass options they do not know up to here.
  app.fallthrough();
  double max_memory_gb = 0;
  app.add_option("--max-memory-gb", max_memory_gb,
                 "memory budget, GB (default: the memory available at start); work estimated "
                 "to need more is refused before it starts")
      ->check(CLI::Range(1e-3, 1e6));
  app.add_flag("--yes-long", weft::cli::run_limits().yes_long,
               "run work estimated to take more than an hour");
  weft::cli::Commands commands;
  // In the order `weft --help` lists them.
  namespace cli = weft::cli;
  for (cli::AddCommand* add :
       {cli::add_slab_command, cli::add_spectrum_command, cli::add_bake_command,
        cli::add_bench_command, cli::add_mie_command, cli::add_medium_command,
        cli::add_table_command, cli::add_render_command, cli::add_sweep_command,
        cli::add_weave_command, cli::add_compare_command, cli::add_merge_command,
        cli::add_slurm_command, cli::add_verify_command, cli::add_scene_command})
    add(app, commands);
  check_seeds(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  weft::cli::run_limits().max_memory_bytes = max_memory_gb * 1e9;
  try {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const weft::Error& e) {
    std::fprintf(stderr, "weft: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // An estimate missed something: still a clear message, and nothing half-written (outputs
    // are written atomically at the end).
    std::fprintf(stderr,
                 "weft: error: out of memory (the work needs more memory than this machine "
                 "can give; use a smaller resolution, image or sample count)\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "weft: internal error: %s\n", e.what());
    return 3;
  }
  return 1;
}
