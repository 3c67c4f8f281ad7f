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
  weft::cli::add_slab_command(app, commands);
  weft::cli::add_spectrum_command(app, commands);
  weft::cli::add_bake_command(app, commands);
  weft::cli::add_bench_command(app, commands);
  weft::cli::add_mie_command(app, commands);
  weft::cli::add_medium_command(app, commands);
  weft::cli::add_table_command(app, commands);
  weft::cli::add_render_command(app, commands);
  weft::cli::add_sweep_command(app, commands);
  weft::cli::add_weave_command(app, commands);
  weft::cli::add_compare_command(app, commands);

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
