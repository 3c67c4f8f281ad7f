// weft slurm: a bake, sweep or verify as a Slurm job array plus a merge job (core/slurm.h). Binds
// the sbatch options, checks the wrapped command as its last shard will run it, and prints the
// scripts (--dry-run) or what was submitted.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/slurm.h"
#include "weft/verify/verify.h"

namespace weft::cli {
namespace {

namespace fs = std::filesystem;

std::string self_path() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("weft") : p.string();
}

// Parses and runs the wrapped command line check-only (RunLimits::check_only): the same parser
// and every check the command makes before its work, none of the work (work_starts stops it).
// Returns the inputs the command guards.
std::vector<NamedPath> check_wrapped_command(const std::vector<std::string>& args) {
  const auto program = make_program();
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  auto inputs = std::make_shared<std::vector<NamedPath>>();
  try {
    program->app.parse(reversed);
    const int code = run_program(*program, inputs);
    if (code != 0)
      throw Error("", "command",
                  "the wrapped command stops with exit code " + std::to_string(code));
  } catch (const WorkWouldStart&) {
  } catch (const CLI::ParseError& e) {
    throw Error("", "command", std::string("the wrapped command: ") + e.what());
  }
  return *inputs;
}

// The output's folder is created for the check (the shards' part files go there) and removed
// again when the check fails or nothing is submitted, unless it was there before.
class ScriptFolder {
 public:
  explicit ScriptFolder(fs::path dir) : dir_(std::move(dir)) {
    std::error_code ec;
    created_ = fs::create_directory(dir_, ec);
    if (ec) throw Error(dir_.string(), "--output", "cannot create the script folder");
  }
  ~ScriptFolder() {
    std::error_code ec;
    if (created_ && !keep_) fs::remove_all(dir_, ec);
  }
  void keep() { keep_ = true; }
  bool created() const { return created_; }

 private:
  fs::path dir_;
  bool created_ = false, keep_ = false;
};

// The scripts of a wrapped command line (checked before any is written: its values, then the
// last shard's command as it will run, then the scripts, parts and output against every file that
// command reads), submitted or printed.
int run_slurm(SlurmRequest o, const RunLimits& limits) {
  o.working_folder = fs::current_path().string();
  o.program = self_path();
  const SlurmPlan p = plan_slurm(o, [&](const SlurmPlan& plan) {
    // verify's output is its report folder.
    if (plan.verify)
      check_verify_output(plan.output);
    else
      validate_output_paths(limits, {{plan.output, "--output"}}, {});
  });
  ScriptFolder folder(p.folder);
  const std::vector<NamedPath> inputs = check_wrapped_command(p.last_shard);
  validate_output_paths(limits, p.outputs(), inputs, p.folders());
  const SlurmScripts scripts = slurm_scripts(p);
  if (o.dry_run) {
    std::fputs(slurm_dry_run_text(scripts).c_str(), stdout);
    return 0;
  }
  SlurmSubmission s;
  try {
    s = submit_slurm(scripts);
  } catch (const Error&) {
    // The array job's scripts were removed when nothing was submitted; a folder made for them
    // goes too (the destructor), and the user is told. Otherwise the array job needs it.
    std::error_code ec;
    if (fs::exists(scripts.array_path, ec))
      folder.keep();
    else if (folder.created())
      std::fprintf(stderr, "weft: slurm: removed %s, made for this submission\n",
                   p.folder.string().c_str());
    throw;
  }
  folder.keep();
  std::printf("submitted array job %s (%d shards) and merge job %s -> %s\n", s.array_job.c_str(),
              o.shards, s.merge_job.c_str(), p.output.c_str());
  return 0;
}

}  // namespace

void add_slurm_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<SlurmRequest>();
  auto* sub = app.add_subcommand(
      "slurm",
      "Run `weft bake fiber|fabric ...`, `weft sweep ...` or `weft verify ...` as a Slurm job "
      "array of --shards shards and a merge job after them (scripts in OUTPUT.slurm/)");
  sub->add_option("--shards", o->shards, "number of shards (array tasks)")
      ->required()
      ->check(CLI::Range(1, 10000));
  sub->add_option("--partition", o->partition, "Slurm partition (sbatch --partition)");
  sub->add_option("--time", o->time, "time limit per shard (sbatch --time, e.g. 1:00:00)");
  sub->add_option("--account", o->account, "Slurm account (sbatch --account)");
  sub->add_option("--cpus-per-task", o->cpus, "CPUs per shard (sbatch --cpus-per-task)")
      ->check(CLI::Range(1, 4096));
  sub->add_flag("--dry-run", o->dry_run,
                "print the scripts and the sbatch commands; submit nothing");
  // The wrapped command line is this command's own: keep it here rather than passing it up to
  // weft's global options (program.cpp sets fallthrough for --yes-long / --max-memory-gb).
  sub->allow_extras();
  sub->fallthrough(false);
  sub->footer(
      "Example: weft slurm --shards 8 --partition cpu bake fiber spec.json -o fiber.exr "
      "--photons 1000000\n         weft slurm --shards 16 verify --quality publication -o report");
  commands.push_back({sub, [o, sub](const RunLimits& l) {
                        SlurmRequest r = *o;
                        r.args = sub->remaining();
                        return run_slurm(r, l);
                      }});
}

}  // namespace weft::cli
