#pragma once
// Output files appear whole or not at all: write to a temporary sibling, then rename.
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace weft {

// Calls write(tmp_path) and renames tmp_path to 'path' on success. On any exception the
// temporary is removed and the exception propagates, leaving no half-written 'path'.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp_path)>& write);

// Several outputs, all or none: each is written to its own temporary sibling, and only when every
// one was written are they renamed into place. On an exception every temporary is removed and
// no output is touched.
using FileWriter = std::function<void(const std::filesystem::path& tmp_path)>;
void write_all_atomically(const std::vector<std::pair<std::filesystem::path, FileWriter>>& outputs);

// A path with what it is ("output", "preview", "scene description"), for error messages.
struct NamedPath {
  std::filesystem::path path;
  std::string what;
};

// Checked before any work: every output lies in an existing directory, is not a directory, and
// names neither an existing input nor another output (compared as canonical paths, so "./a.exr"
// and "a.exr" clash). Throws weft::Error naming the output: "is also the <what> file".
void check_output_paths(const std::vector<NamedPath>& outputs,
                        const std::vector<NamedPath>& inputs);

// Same, for text content.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace weft
