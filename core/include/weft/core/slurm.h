#pragma once
// A sharded command as a Slurm job array of N shards (`--shard K/N`) plus a merge job that runs
// after all of them succeeded (`--dependency=afterok`): the request (the wrapped command line and
// the sbatch options), its plan (every value checked for the batch scripts before anything is
// written), the two scripts, and their submission. Bake and sweep shards run with --resume, so a
// shard requeued after a node failure continues from its checkpoint.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"

namespace weft {

struct SlurmRequest {
  int shards = 0;
  std::string partition, time, account;  // empty: Slurm's defaults
  int cpus = 0;                          // per shard; 0: Slurm's default
  bool dry_run = false;                  // print the scripts, submit nothing
  // The wrapped command line, from its command name on: `bake fiber|fabric ...`, `sweep ...` or
  // `verify ...`, with -o OUTPUT.
  std::vector<std::string> args;
  std::string working_folder;  // where the scripts cd to
  std::string program;         // the weft the scripts run
};

struct SlurmPlan {
  SlurmRequest request;
  bool verify = false;           // the output is a report folder
  size_t output_at = 0;          // index of OUTPUT in request.args
  std::filesystem::path output;  // absolute
  std::filesystem::path folder;  // OUTPUT.slurm: the scripts, the parts and the logs
  std::string weave_out;         // bake fabric --weave-out: the merge writes it
  // The last shard's command line, as the array script runs it for task N-1: the last shard
  // always has work (shard_units), so a check-only run of it ends where the work would start.
  std::vector<std::string> last_shard;
  std::filesystem::path part(int k) const;
  // The files the job writes (scripts, parts, the output and weave table unless verify) and the
  // folders it replaces (the script folder; verify's report folder), for the output guard.
  std::vector<NamedPath> outputs() const;
  std::vector<NamedPath> folders() const;
};

// weft::Error naming the option at fault: an unknown wrapped command, --shard or --resume given
// (weft slurm sets them), verify --fit (one process), no -o, a control character in any value or
// in the working folder, --time/--partition/--account outside Slurm's syntax, an output path an
// #SBATCH line cannot hold. 'check_output' runs between the checks of the values and of the script
// folder's path: the front end's check of the output (the output guard, or verify's report folder).
SlurmPlan plan_slurm(const SlurmRequest& request,
                     const std::function<void(const SlurmPlan&)>& check_output);

struct SlurmScripts {
  std::filesystem::path array_path, merge_path;
  std::string array, merge;
};
SlurmScripts slurm_scripts(const SlurmPlan& plan);
// What --dry-run prints: both scripts and the two sbatch commands that submit them.
std::string slurm_dry_run_text(const SlurmScripts& scripts);

// Writes the scripts and submits them with sbatch; the two job ids. weft::Error naming the
// script when a submission fails: the array's (nothing submitted) after removing both scripts,
// saying so; the merge's (the array job runs) with the scripts kept and the array job named.
struct SlurmSubmission {
  std::string array_job, merge_job;
};
SlurmSubmission submit_slurm(const SlurmScripts& scripts);

// A word for a POSIX shell: in single quotes, each ' written as '\''.
std::string shell_quote(const std::string& s);

}  // namespace weft
