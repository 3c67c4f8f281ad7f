// The weft program: its global options and every subcommand, built once by main() and once more by
// weft slurm to check the command it wraps exactly as that command would run.
#include <cstdio>

#include "commands.h"

namespace weft::cli {
namespace {

// Every --seed of every subcommand takes only plain decimal seeds (cli::seed_validator).
void check_seeds(CLI::App& app) {
  for (CLI::Option* o : app.get_options())
    if (o->check_lname("seed")) o->check(seed_validator());
  for (CLI::App* sub : app.get_subcommands({})) check_seeds(*sub);
}

}  // namespace

std::unique_ptr<Program> make_program() {
  auto p = std::make_unique<Program>();
  CLI::App& app = p->app;
  app.set_version_flag("--version", WEFT_VERSION);
  app.require_subcommand(1);
  // The run's limits may follow the subcommand ("weft bake fiber ... --yes-long"): subcommands
  // made after this pass options they do not know up to here.
  app.fallthrough();
  app.add_option("--max-memory-gb", p->max_memory_gb,
                 "memory budget, GB, at least 0.05 (default: the memory available at start); "
                 "work estimated to need more is refused before it starts")
      ->check(finite_range(kMinMemoryGb, 1e6));
  app.add_flag("--yes-long", p->yes_long, "run work estimated to take more than an hour");
  // In the order `weft --help` lists them.
  for (AddCommand* add :
       {add_slab_command, add_spectrum_command, add_bake_command, add_bench_command,
        add_mie_command, add_medium_command, add_table_command, add_render_command,
        add_sweep_command, add_weave_command, add_compare_command, add_merge_command,
        add_slurm_command, add_verify_command, add_scene_command, add_export_command,
        add_view_command})
    add(app, p->commands);
  check_seeds(app);
  return p;
}

int run_program(const Program& p, std::shared_ptr<std::vector<NamedPath>> check_only_inputs) {
  RunLimits limits = program_limits(p.max_memory_gb, p.yes_long);
  limits.check_only = check_only_inputs != nullptr;
  limits.guarded_inputs = std::move(check_only_inputs);
  for (const auto& c : p.commands)
    if (c.app->parsed()) return c.run(limits);
  return 1;
}

}  // namespace weft::cli
