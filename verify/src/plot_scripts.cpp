#include "weft/verify/plot_scripts.h"

#include <cstdlib>
#include <system_error>

#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/parallel.h"

namespace weft {
namespace {

// A shell word: in single quotes, each ' written as '\''.
std::string quoted(const std::string& s) {
  std::string q(1, '\'');
  for (char c : s) {
    if (c == '\'') {
      q.append("'\\''");
    } else {
      q.push_back(c);
    }
  }
  q.push_back('\'');
  return q;
}

std::filesystem::path find_script(const std::string& script) {
  std::string tried;
  const auto path = find_bundled_file(std::filesystem::path("tools") / script, &tried);
  if (path.empty()) throw Error(script, "", "plot script not found (tried: " + tried + ")");
  return path;
}

}  // namespace

void run_plot_script(const std::string& script, const std::vector<std::string>& args,
                     const std::filesystem::path& output) {
  const std::string python = "/usr/bin/python3";
  std::error_code ec;
  if (!std::filesystem::exists(python, ec))
    throw Error(output.string(), "",
                "cannot plot: " + python + " is missing (install python3-matplotlib)");
  std::string cmd = python;
  for (const auto& word : {find_script(script).string()}) cmd.append(" ").append(quoted(word));
  for (const auto& a : args) cmd.append(" ").append(quoted(a));
  if (std::system(cmd.c_str()) != 0)
    throw Error(output.string(), "", "the plot script failed (" + script + ")");
}

void plot_verify_figures(const std::filesystem::path& staging, const std::filesystem::path& output,
                         int threads) {
  run_plot_script(
      "plot_verify.py",
      {"--jobs", std::to_string(thread_count(threads)), (staging / "inplane.csv").string(),
       (staging / "metrics.json").string(), staging.string()},
      output);
}

}  // namespace weft
