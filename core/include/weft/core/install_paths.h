#pragma once
// Files the program ships beside its code (measured data, the verify suite, example scenes, plot
// scripts), each named by its path in the source tree ("materials/data/measured/..."). An installed
// program finds them under <prefix>/share/weft/<that path> (where `cmake --install` puts them,
// beside <prefix>/bin/weft); a program run from its build tree, in the source tree it was built
// from.
#include <filesystem>
#include <string>
#include <vector>

namespace weft {

// Where bundled data is looked for, in order: <folder of this executable>/../share/weft (an
// installed program, wherever its prefix was copied), or the folder a front end loaded into
// another program named (set_installed_data_root), then the source tree of the build.
std::vector<std::filesystem::path> bundled_data_roots();

// A front end loaded into another program (the Python module, python/, runs in python3, whose
// executable says nothing about Weft's prefix) names its installed share/weft itself, from where
// its own file lies; it then replaces the executable's.
void set_installed_data_root(const std::filesystem::path& root);

// The first regular file root / rel over 'roots'. Empty when none exists; 'tried' (when given)
// then lists the places looked at, for the caller's error.
std::filesystem::path find_file_under(const std::vector<std::filesystem::path>& roots,
                                      const std::filesystem::path& rel,
                                      std::string* tried = nullptr);

// The bundled file 'rel' (a path in the source tree): find_file_under(bundled_data_roots(), ...).
std::filesystem::path find_bundled_file(const std::filesystem::path& rel,
                                        std::string* tried = nullptr);

}  // namespace weft
