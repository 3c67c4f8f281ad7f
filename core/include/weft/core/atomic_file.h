#pragma once
// Output files appear whole or not at all: write to a temporary sibling, then rename.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
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

// The temporary sibling write_atomically writes 'path' through:
// ".tmp-<stem>-<host>@<pid>-<n>-partial<ext>", a name of its own per process and call (writers of
// one path never share one), the extension last (writers such as OpenImageIO choose the format by
// it). A process killed mid-write (SIGKILL) leaves it behind, so naming one first removes the stale
// temporaries of 'path' (remove_stale_temporaries). weft::Error when the directory is missing.
std::filesystem::path temporary_sibling(const std::filesystem::path& path);

// Removes the temporaries of 'path' (files or folders named as temporary_sibling names them) whose
// writer ran on this host and no longer exists (kill(pid, 0) fails with ESRCH). Those of live
// processes and of other hosts (a shared file system) are left alone. Returns how many it removed.
size_t remove_stale_temporaries(const std::filesystem::path& path);

// Same, for text content.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);
// Same, for binary content.
void write_bytes_atomically(const std::filesystem::path& path, std::span<const uint8_t> bytes);

}  // namespace weft
