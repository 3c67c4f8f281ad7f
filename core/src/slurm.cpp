#include "weft/core/slurm.h"

#include <array>
#include <cstdio>
#include <regex>

#include "weft/core/error.h"

namespace weft {
namespace {

namespace fs = std::filesystem;

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

// The values that go into the scripts: no control characters in any, Slurm's syntax for its own.
void check_slurm_values(const SlurmRequest& o) {
  const std::vector<std::string>& args = o.args;
  for (size_t i = 0; i < args.size(); ++i)
    refuse_control_characters(args[i],
                              i > 0 && args[i - 1].rfind("-", 0) == 0 ? args[i - 1] : "command");
  if (!o.time.empty()) check_slurm_time(o.time);
  if (!o.partition.empty()) check_slurm_name(o.partition, "--partition", true);
  if (!o.account.empty()) check_slurm_name(o.account, "--account", false);
}

// The #SBATCH header of a script.
std::string directives(const SlurmRequest& o, const fs::path& folder, const std::string& job_name,
                       const std::string& log) {
  std::string s = "#!/bin/bash\n#SBATCH --job-name=" + sbatch_value(job_name) +
                  "\n#SBATCH --output=" + sbatch_value((folder / log).string()) + "\n";
  if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time.empty()) s += "#SBATCH --time=" + o.time + "\n";
  if (!o.account.empty()) s += "#SBATCH --account=" + o.account + "\n";
  if (o.cpus) s += "#SBATCH --cpus-per-task=" + std::to_string(o.cpus) + "\n";
  return s;
}

}  // namespace

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

fs::path SlurmPlan::part(int k) const {
  return folder / ("part-" + std::to_string(k) + ".part");
}

std::vector<NamedPath> SlurmPlan::outputs() const {
  std::vector<NamedPath> out = {{folder / "array.sh", "array script"},
                                {folder / "merge.sh", "merge script"}};
  for (int k = 0; k < request.shards; ++k) out.push_back({part(k), "part file"});
  if (!verify) out.push_back({output, "--output"});
  if (!weave_out.empty()) out.push_back({fs::absolute(weave_out), "--weave-out"});
  return out;
}

std::vector<NamedPath> SlurmPlan::folders() const {
  std::vector<NamedPath> out = {{folder, "script folder"}};
  if (verify) out.push_back({output, "--output"});
  return out;
}

SlurmPlan plan_slurm(const SlurmRequest& o,
                     const std::function<void(const SlurmPlan&)>& check_output) {
  const std::vector<std::string>& args = o.args;
  SlurmPlan p;
  p.request = o;
  p.verify = !args.empty() && args[0] == "verify";
  if (args.size() < 2 || !((args[0] == "bake" && (args[1] == "fiber" || args[1] == "fabric")) ||
                           args[0] == "sweep" || p.verify))
    throw Error("", "command",
                "expected `bake fiber ...`, `bake fabric ...`, `sweep ...` or `verify ...`");
  std::string output;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--weave-out" && i + 1 < args.size()) p.weave_out = args[i + 1];
    if (args[i].rfind("--weave-out=", 0) == 0) p.weave_out = args[i].substr(12);
    if (args[i] == "--shard" || args[i].rfind("--shard=", 0) == 0 || args[i] == "--resume")
      throw Error("", args[i], "is set by weft slurm for each shard");
    if (p.verify && args[i] == "--fit")
      throw Error("", "--fit", "runs in one process: not as Slurm shards");
    if ((args[i] == "-o" || args[i] == "--output") && i + 1 < args.size())
      output = args[i + 1], p.output_at = i + 1;
  }
  if (output.empty()) throw Error("", "--output", "the command needs -o OUTPUT");
  check_slurm_values(o);
  p.output = fs::absolute(output);
  p.folder = p.output.string() + ".slurm";
  refuse_control_characters(o.working_folder, "the working folder");
  check_output(p);
  check_sbatch_path(p.folder);
  const int n = o.shards;
  p.last_shard = args;
  p.last_shard[p.output_at] = p.part(n - 1).string();
  p.last_shard.insert(p.last_shard.end(),
                      {"--shard", std::to_string(n - 1) + "/" + std::to_string(n)});
  if (!p.verify) p.last_shard.push_back("--resume");
  p.last_shard.push_back("--quiet");
  return p;
}

SlurmScripts slurm_scripts(const SlurmPlan& p) {
  const SlurmRequest& o = p.request;
  const int n = o.shards;
  const std::string name = "weft-" + p.output.filename().string();
  SlurmScripts s{p.folder / "array.sh", p.folder / "merge.sh", "", ""};
  s.array = directives(o, p.folder, name, "shard-%a.log");
  s.array += "#SBATCH --array=0-" + std::to_string(n - 1) + "\n#SBATCH --requeue\nset -eu\ncd " +
             shell_quote(o.working_folder) + "\nexec " + shell_quote(o.program);
  for (size_t i = 0; i < o.args.size(); ++i)
    s.array += " " + (i == p.output_at ? shell_quote((p.folder / "part-").string()) +
                                             "\"$SLURM_ARRAY_TASK_ID\".part"
                                       : shell_quote(o.args[i]));
  // A requeued shard continues from its checkpoint; verify's shards start again (their
  // fiber bake is cached, bake_cache.h).
  s.array += " --shard \"$SLURM_ARRAY_TASK_ID/" + std::to_string(n) + "\"" +
             (p.verify ? "" : " --resume") + " --quiet\n";
  s.merge = directives(o, p.folder, name + "-merge", "merge.log");
  s.merge += "set -eu\ncd " + shell_quote(o.working_folder) + "\nexec " + shell_quote(o.program) +
             " merge";
  for (int k = 0; k < n; ++k) s.merge += " " + shell_quote(p.part(k).string());
  s.merge += " -o " + shell_quote(p.output.string());
  if (!p.weave_out.empty())
    s.merge += " --weave-out " + shell_quote(fs::absolute(p.weave_out).string());
  s.merge += "\n";
  return s;
}

std::string slurm_dry_run_text(const SlurmScripts& s) {
  return "# " + s.array_path.string() + "\n" + s.array + "\n# " + s.merge_path.string() + "\n" +
         s.merge + "\n# submit with:\n#   jobid=$(sbatch --parsable " +
         shell_quote(s.array_path.string()) + ")\n#   sbatch --dependency=afterok:${jobid%%;*} " +
         shell_quote(s.merge_path.string()) + "\n";
}

SlurmSubmission submit_slurm(const SlurmScripts& s) {
  write_text_atomically(s.array_path, s.array);
  write_text_atomically(s.merge_path, s.merge);
  const auto [id_text, status] =
      run_capture("sbatch --parsable " + shell_quote(s.array_path.string()));
  const std::string id = id_text.substr(0, id_text.find_first_of(";\n"));
  if (status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    // Nothing was submitted: the scripts would only mislead.
    std::string removed;
    for (const auto& f : {s.array_path, s.merge_path}) {
      std::error_code ec;
      if (std::filesystem::remove(f, ec)) removed += (removed.empty() ? "" : " and ") + f.string();
    }
    throw Error(s.array_path.string(), "sbatch",
                "submission failed: " + id_text +
                    (removed.empty() ? "" : "; nothing was submitted, removed " + removed));
  }
  const auto [mid_text, mstatus] = run_capture("sbatch --parsable --dependency=afterok:" + id +
                                               " " + shell_quote(s.merge_path.string()));
  const std::string mid = mid_text.substr(0, mid_text.find_first_of(";\n"));
  // The array job runs and needs its folder: the scripts stay, and the user is told.
  if (mstatus != 0 || mid.empty())
    throw Error(s.merge_path.string(), "sbatch",
                "submission failed: " + mid_text + "; array job " + id +
                    " was submitted without its merge and its scripts stay: cancel it (scancel " +
                    id + ") or submit this script after it (sbatch --dependency=afterok:" + id +
                    ")");
  return {id, mid};
}

}  // namespace weft
