#include "plot_util.h"

#include <cstdlib>
#include <system_error>

#include "weft/core/error.h"

#ifndef WEFT_TOOLS_DIR
#define WEFT_TOOLS_DIR ""
#endif

namespace weft::cli {
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
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> candidates;
  if (std::string(WEFT_TOOLS_DIR).size()) candidates.push_back(fs::path(WEFT_TOOLS_DIR) / script);
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / ".." / "share" / "weft" / "tools" / script);
  std::string tried;
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c;
    tried += (tried.empty() ? "" : ", ") + c.string();
  }
  throw Error(script, "", "plot script not found (tried: " + tried + ")");
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

}  // namespace weft::cli
