// weft slurm: a bake, sweep or verify as a Slurm job array of N shards (`--shard K/N`) plus a
// merge job that runs after all of them succeeded (`--dependency=afterok`). Writes the two batch
// scripts beside the output and submits them with sbatch, or prints them (--dry-run) for users who
// submit themselves. Bake and sweep shards run with --resume: a shard requeued after a node
// failure continues from its checkpoint.
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/verify/verify.h"

namespace weft::cli {
namespace {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Runs 'command', returns its stdout and exit status.
std::pair<std::string, int> run_capture(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {"", -1};
  std::array<char, 256> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  const int status = ::pclose(pipe);
  return {out, status};
}

std::string self_path() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("weft") : p.string();
}

struct SlurmOptions {
  int shards = 0;
  std::string partition, time, account;
  int cpus = 0;
  bool dry_run = false;
};

// Nothing of the user's may end a line of a batch script or hide in it: no control characters
// (a newline in --time wrote a line of the user's choosing into the #SBATCH header).
void refuse_control_characters(const std::string& value, const std::string& option) {
  for (unsigned char c : value)
    if (c < 0x20 || c == 0x7f)
      throw Error("", option,
                  "holds a control character (a newline, a tab...): not in a batch script");
}

// Slurm's time formats (sbatch --time): MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS.
void check_slurm_time(const std::string& t) {
  static const std::regex time(R"((\d+-\d+(:\d+(:\d+)?)?|\d+(:\d+(:\d+)?)?|UNLIMITED|INFINITE))");
  refuse_control_characters(t, "--time");
  if (!std::regex_match(t, time))
    throw Error("", "--time",
                "'" + t + "' is not a Slurm time: [[D-]HH:]MM[:SS] (1:00:00, 2-12, 90)");
}

// Partition and account names: letters, digits, '_', '.', '-' (partitions: a comma list).
void check_slurm_name(const std::string& v, const std::string& option, bool list) {
  static const std::regex name(R"([A-Za-z0-9_.-]+)"),
      names(R"([A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*)");
  refuse_control_characters(v, option);
  if (!std::regex_match(v, list ? names : name))
    throw Error("", option,
                "'" + v + "' is not a Slurm name (letters, digits, '_', '.', '-'" +
                    (list ? ", a comma list" : "") + ")");
}

// A path in an #SBATCH line: sbatch reads the line itself (no shell), expands '%' patterns and
// takes double quotes as quoting, so the user's part of it may hold neither.
void check_sbatch_path(const fs::path& p) {
  const std::string s = p.string();
  refuse_control_characters(s, "--output");
  if (s.find_first_of("%\"\\") != std::string::npos)
    throw Error(s, "--output", "a path with '%', '\"' or '\\' cannot go into an #SBATCH line");
}

// An #SBATCH value, double-quoted when it holds a space.
std::string sbatch_value(const std::string& s) {
  return s.find(' ') == std::string::npos ? s : "\"" + s + "\"";
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

 private:
  fs::path dir_;
  bool created_ = false, keep_ = false;
};

// The values that go into the scripts: no control characters in any, Slurm's syntax for its own.
void check_slurm_values(const SlurmOptions& o, const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i)
    refuse_control_characters(args[i],
                              i > 0 && args[i - 1].rfind("-", 0) == 0 ? args[i - 1] : "command");
  if (!o.time.empty()) check_slurm_time(o.time);
  if (!o.partition.empty()) check_slurm_name(o.partition, "--partition", true);
  if (!o.account.empty()) check_slurm_name(o.account, "--account", false);
}

// The scripts of a wrapped command line 'args' (checked before any is written), submitted or
// printed.
int run_slurm(const SlurmOptions& o, const std::vector<std::string>& args,
              const RunLimits& limits) {
  const bool verify = !args.empty() && args[0] == "verify";
  if (args.size() < 2 || !((args[0] == "bake" && (args[1] == "fiber" || args[1] == "fabric")) ||
                           args[0] == "sweep" || verify))
    throw Error("", "command",
                "expected `bake fiber ...`, `bake fabric ...`, `sweep ...` or `verify ...`");
  std::string output, weave_out;  // bake fabric --weave-out: the merge writes it
  size_t output_at = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--weave-out" && i + 1 < args.size()) weave_out = args[i + 1];
    if (args[i].rfind("--weave-out=", 0) == 0) weave_out = args[i].substr(12);
    if (args[i] == "--shard" || args[i].rfind("--shard=", 0) == 0 || args[i] == "--resume")
      throw Error("", args[i], "is set by weft slurm for each shard");
    if (verify && args[i] == "--fit")
      throw Error("", "--fit", "runs in one process: not as Slurm shards");
    if ((args[i] == "-o" || args[i] == "--output") && i + 1 < args.size())
      output = args[i + 1], output_at = i + 1;
  }
  if (output.empty()) throw Error("", "--output", "the command needs -o OUTPUT");
  check_slurm_values(o, args);
  const fs::path out_abs = fs::absolute(output);
  const fs::path dir = out_abs.string() + ".slurm";
  const std::string cwd = fs::current_path().string(), weft = self_path();
  refuse_control_characters(cwd, "the working folder");
  // verify's output is its report folder.
  if (verify)
    check_verify_output(out_abs);
  else
    validate_output_paths(limits, {{out_abs, "--output"}}, {});
  check_sbatch_path(dir);
  const std::string name = "weft-" + out_abs.filename().string();
  const int n = o.shards;
  auto part = [&](int k) { return dir / ("part-" + std::to_string(k) + ".part"); };
  // The last shard's command line, as the array script runs it for task N-1: the last shard
  // always has work (shard_units), so its check ends where the work would start and writes
  // nothing.
  std::vector<std::string> last = args;
  last[output_at] = part(n - 1).string();
  last.insert(last.end(), {"--shard", std::to_string(n - 1) + "/" + std::to_string(n)});
  if (!verify) last.push_back("--resume");
  last.push_back("--quiet");
  ScriptFolder folder(dir);
  // That shard's command, checked as it will run; then the scripts, the parts and
  // the output against every file it reads.
  const std::vector<NamedPath> inputs = check_wrapped_command(last);
  std::vector<NamedPath> outputs = {{dir / "array.sh", "array script"},
                                    {dir / "merge.sh", "merge script"}};
  for (int k = 0; k < n; ++k) outputs.push_back({part(k), "part file"});
  if (!verify) outputs.push_back({out_abs, "--output"});
  if (!weave_out.empty()) outputs.push_back({fs::absolute(weave_out), "--weave-out"});
  std::vector<NamedPath> folders = {{dir, "script folder"}};
  if (verify) folders.push_back({out_abs, "--output"});
  validate_output_paths(limits, outputs, inputs, folders);

  auto directives = [&](const std::string& job_name, const std::string& log) {
    std::string s = "#!/bin/bash\n#SBATCH --job-name=" + sbatch_value(job_name) +
                    "\n#SBATCH --output=" + sbatch_value((dir / log).string()) + "\n";
    if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
    if (!o.time.empty()) s += "#SBATCH --time=" + o.time + "\n";
    if (!o.account.empty()) s += "#SBATCH --account=" + o.account + "\n";
    if (o.cpus) s += "#SBATCH --cpus-per-task=" + std::to_string(o.cpus) + "\n";
    return s;
  };
  std::string array = directives(name, "shard-%a.log");
  array += "#SBATCH --array=0-" + std::to_string(n - 1) + "\n#SBATCH --requeue\nset -eu\ncd " +
           shell_quote(cwd) + "\nexec " + shell_quote(weft);
  for (size_t i = 0; i < args.size(); ++i)
    array += " " + (i == output_at
                        ? shell_quote((dir / "part-").string()) + "\"$SLURM_ARRAY_TASK_ID\".part"
                        : shell_quote(args[i]));
  // A requeued shard continues from its checkpoint; verify's shards start again (their
  // fiber bake is cached, bake_cache.h).
  array += " --shard \"$SLURM_ARRAY_TASK_ID/" + std::to_string(n) + "\"" +
           (verify ? "" : " --resume") + " --quiet\n";
  std::string merge = directives(name + "-merge", "merge.log");
  merge += "set -eu\ncd " + shell_quote(cwd) + "\nexec " + shell_quote(weft) + " merge";
  for (int k = 0; k < n; ++k) merge += " " + shell_quote(part(k).string());
  merge += " -o " + shell_quote(out_abs.string());
  if (!weave_out.empty()) merge += " --weave-out " + shell_quote(fs::absolute(weave_out).string());
  merge += "\n";

  const fs::path array_sh = dir / "array.sh", merge_sh = dir / "merge.sh";
  if (o.dry_run) {
    std::printf(
        "# %s\n%s\n# %s\n%s\n# submit with:\n#   jobid=$(sbatch --parsable %s)\n"
        "#   sbatch --dependency=afterok:${jobid%%%%;*} %s\n",
        array_sh.c_str(), array.c_str(), merge_sh.c_str(), merge.c_str(),
        shell_quote(array_sh.string()).c_str(), shell_quote(merge_sh.string()).c_str());
    return 0;
  }
  folder.keep();
  write_text_atomically(array_sh, array);
  write_text_atomically(merge_sh, merge);
  const auto [id_text, status] = run_capture("sbatch --parsable " + shell_quote(array_sh.string()));
  const std::string id = id_text.substr(0, id_text.find_first_of(";\n"));
  if (status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw Error(array_sh.string(), "sbatch", "submission failed: " + id_text);
  const auto [mid_text, mstatus] = run_capture("sbatch --parsable --dependency=afterok:" + id +
                                               " " + shell_quote(merge_sh.string()));
  const std::string mid = mid_text.substr(0, mid_text.find_first_of(";\n"));
  if (mstatus != 0 || mid.empty())
    throw Error(merge_sh.string(), "sbatch", "submission failed: " + mid_text);
  std::printf("submitted array job %s (%d shards) and merge job %s -> %s\n", id.c_str(), n,
              mid.c_str(), out_abs.c_str());
  return 0;
}

}  // namespace

void add_slurm_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<SlurmOptions>();
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
  commands.push_back(
      {sub, [o, sub](const RunLimits& l) { return run_slurm(*o, sub->remaining(), l); }});
}

}  // namespace weft::cli
