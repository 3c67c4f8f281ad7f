#pragma once
// A mistyped name on the command line ("weft rendr", "--qiet") answered with the nearest valid
// one: CLI11 only says which arguments it did not expect.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace weft::cli {

// Optimal string alignment distance: inserting, deleting or changing a character, or swapping
// two neighbours, costs 1 each ("rendr" -> "render" 1, "preveiw" -> "preview" 1).
size_t edit_distance(const std::string& a, const std::string& b);

// The candidate nearest 'word' when it is close enough to be a typo of it: at most a third of
// the word's characters off (at least 1). Empty when none is; the first of equally near ones.
std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates);

// Prints the error of a failed parse of the weft program 'app' on stderr and returns the exit
// code. An unknown option or subcommand is named alone, with the nearest valid name; other
// errors are CLI11's own (app.exit).
int report_parse_error(CLI::App& app, const CLI::ParseError& e);

}  // namespace weft::cli
