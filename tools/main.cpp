// weft: the command-line front end of the Weft fabric appearance pipeline.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "commands.h"
#include "weft/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"Weft: physically based fabric appearance pipeline and renderer", "weft"};
  app.set_version_flag("--version", WEFT_VERSION);
  app.require_subcommand(1);
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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const weft::Error& e) {
    std::fprintf(stderr, "weft: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "weft: internal error: %s\n", e.what());
    return 3;
  }
  return 1;
}
