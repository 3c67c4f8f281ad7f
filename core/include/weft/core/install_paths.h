#pragma once
// Files the program ships beside its code (measured data, plot scripts): found in the source tree
// the build was made from, or in an installed tree laid out as <prefix>/bin/weft and
// <prefix>/share/weft/<subdir>/...
#include <filesystem>
#include <string>

namespace weft {

// The first regular file among 'source_dir' / rel (skipped when source_dir is empty) and
// <folder of this executable>/../share/weft/<share_subdir>/rel. Empty when none exists; 'tried'
// (when given) then lists the places looked at, for the caller's error.
std::filesystem::path find_installed_file(const std::string& source_dir,
                                          const std::string& share_subdir,
                                          const std::filesystem::path& rel,
                                          std::string* tried = nullptr);

}  // namespace weft
