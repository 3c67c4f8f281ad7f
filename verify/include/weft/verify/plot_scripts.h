#pragma once
// Plots are drawn by the project's matplotlib scripts in tools/ (installed to share/weft/tools),
// always with /usr/bin/python3: the python3 first on PATH may lack matplotlib.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace weft {

// Runs tools/<script> with the arguments (core/child_process.h), asking keep_going() as it runs:
// false once it said stop (the script and its workers ended, whatever they wrote is the
// caller's to remove). weft::Error naming the output when the script cannot run or fails.
bool run_plot_script(
    const std::string& script, const std::vector<std::string>& args,
    const std::filesystem::path& output,
    const std::function<bool()>& keep_going = [] { return true; });

// The figures of a verify report (tools/plot_verify.py) from the inplane.csv and metrics.json in
// 'staging', into it, drawn in as many processes as 'threads' (0: all cores): a figure takes
// about a second, most of a draft run's time. Errors name 'output'; false when keep_going() said
// stop.
bool plot_verify_figures(
    const std::filesystem::path& staging, const std::filesystem::path& output, int threads,
    const std::function<bool()>& keep_going = [] { return true; });

}  // namespace weft
