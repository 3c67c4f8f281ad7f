#pragma once
// Plots are drawn by the project's matplotlib scripts in tools/ (installed to share/weft/tools),
// always with /usr/bin/python3: the python3 first on PATH may lack matplotlib.
#include <filesystem>
#include <string>
#include <vector>

namespace weft::cli {

// Runs tools/<script> with the arguments; weft::Error naming the output when it cannot.
void run_plot_script(const std::string& script, const std::vector<std::string>& args,
                     const std::filesystem::path& output);

}  // namespace weft::cli
