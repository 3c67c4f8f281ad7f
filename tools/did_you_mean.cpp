#include "did_you_mean.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace weft::cli {
namespace {

// The subcommands the parse chose, from the program down to the deepest.
std::vector<CLI::App*> parsed_chain(CLI::App& app) {
  std::vector<CLI::App*> chain = {&app};
  for (auto subs = app.get_subcommands(); !subs.empty(); subs = subs.front()->get_subcommands())
    chain.push_back(subs.front());
  return chain;
}

// The arguments no option or positional took, over 'chain', except where a subcommand takes
// extra arguments on purpose (weft slurm passes them to the command it wraps).
std::vector<std::string> unexpected_arguments(const std::vector<CLI::App*>& chain) {
  std::vector<std::string> out;
  for (CLI::App* a : chain)
    if (!a->get_allow_extras())
      for (const auto& arg : a->remaining(false)) out.push_back(arg);
  return out;
}

// "--name" and "-n" of every option of 'chain' (an option of a parent applies below it).
std::vector<std::string> option_names(const std::vector<CLI::App*>& chain) {
  std::vector<std::string> out;
  for (CLI::App* a : chain)
    for (const CLI::Option* o : a->get_options()) {
      for (const auto& n : o->get_lnames()) out.push_back("--" + n);
      for (const auto& n : o->get_snames()) out.push_back("-" + n);
    }
  return out;
}

std::string command_path(const std::vector<CLI::App*>& chain) {
  std::string path;
  for (CLI::App* a : chain) path += (path.empty() ? "" : " ") + a->get_name();
  return path;
}

int report(const std::string& what, const std::string& suggestion) {
  std::fprintf(stderr, "weft: error: %s%s\nRun with --help for more information.\n", what.c_str(),
               suggestion.empty() ? "" : ("; did you mean '" + suggestion + "'?").c_str());
  return static_cast<int>(CLI::ExitCodes::ExtrasError);
}

}  // namespace

size_t edit_distance(const std::string& a, const std::string& b) {
  // d[i][j]: the distance of a[0, i) and b[0, j).
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  std::iota(d[0].begin(), d[0].end(), size_t{0});
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t change = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + change});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates) {
  const size_t limit = std::max<size_t>(1, word.size() / 3);
  std::string best;
  size_t best_distance = limit + 1;
  for (const auto& c : candidates) {
    const size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

int report_parse_error(CLI::App& app, const CLI::ParseError& e) {
  const bool extras = dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr;
  // A required option or subcommand "missing" is often a typo of it (weft rendr, --ouput).
  const bool required = dynamic_cast<const CLI::RequiredError*>(&e) != nullptr;
  if (!extras && !required) return app.exit(e);
  const auto chain = parsed_chain(app);
  const auto args = unexpected_arguments(chain);
  std::vector<std::string> words, options;
  for (const auto& arg : args) (arg.size() >= 2 && arg[0] == '-' ? options : words).push_back(arg);
  // A word where a subcommand was due: a typo of one when it is near one (the options after it
  // were that subcommand's), else named when no option is amiss.
  std::vector<std::string> commands;
  for (const CLI::App* s : chain.back()->get_subcommands({})) commands.push_back(s->get_name());
  if (!commands.empty())
    for (const auto& w : words)
      if (const auto near = nearest_name(w, commands); !near.empty())
        return report("unknown command '" + w + "' for '" + command_path(chain) + "'", near);
  // An unknown option alone: CLI11 lists every stray word beside it, the scene file among them
  // when the option's value took the scene's place.
  if (!options.empty()) {
    const std::string name = options.front().substr(0, options.front().find('='));
    const bool long_name = name.rfind("--", 0) == 0 && name.size() >= 5;  // "--" and 3 letters
    return report("unknown option '" + name + "' for '" + command_path(chain) + "'",
                  long_name ? nearest_name(name, option_names(chain)) : "");
  }
  if (!commands.empty() && !words.empty())
    return report("unknown command '" + words.front() + "' for '" + command_path(chain) + "'", "");
  return app.exit(e);
}

}  // namespace weft::cli
