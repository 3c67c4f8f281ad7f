// weft: the command-line front end of the Weft fabric appearance pipeline.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>

#include "commands.h"
#include "did_you_mean.h"
#include "weft/core/error.h"

int main(int argc, char** argv) {
  // First thing: a Ctrl-C while the command reads its inputs is an orderly exit 130 too, not the
  // default action's death by signal.
  weft::cli::install_interrupt_handler();
  const auto program = weft::cli::make_program();
  try {
    program->app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return weft::cli::report_parse_error(program->app, e);
  }
  try {
    return weft::cli::run_program(*program);
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
}
