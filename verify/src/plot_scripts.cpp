#include "weft/verify/plot_scripts.h"

#include <system_error>

#include "weft/core/child_process.h"
#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/parallel.h"

namespace weft {
namespace {

std::filesystem::path find_script(const std::string& script) {
  std::string tried;
  const auto path = find_bundled_file(std::filesystem::path("tools") / script, &tried);
  if (path.empty()) throw Error(script, "", "plot script not found (tried: " + tried + ")");
  return path;
}

}  // namespace

bool run_plot_script(const std::string& script, const std::vector<std::string>& args,
                     const std::filesystem::path& output, const std::function<bool()>& keep_going) {
  const std::string python = "/usr/bin/python3";
  std::error_code ec;
  if (!std::filesystem::exists(python, ec))
    throw Error(output.string(), "",
                "cannot plot: " + python + " is missing (install python3-matplotlib)");
  std::vector<std::string> argv = {python, find_script(script).string()};
  argv.insert(argv.end(), args.begin(), args.end());
  const ChildOutcome r = run_child_process(argv, keep_going);
  if (r.stopped) return false;
  if (r.exit_code != 0) throw Error(output.string(), "", "the plot script failed (" + script + ")");
  return true;
}

bool plot_verify_figures(const std::filesystem::path& staging, const std::filesystem::path& output,
                         int threads, const std::function<bool()>& keep_going) {
  return run_plot_script(
      "plot_verify.py",
      {"--jobs", std::to_string(thread_count(threads)), (staging / "inplane.csv").string(),
       (staging / "metrics.json").string(), staging.string()},
      output, keep_going);
}

}  // namespace weft
