#include "weft/core/install_paths.h"

#include <system_error>
#include <vector>

namespace weft {

std::filesystem::path find_installed_file(const std::string& source_dir,
                                          const std::string& share_subdir,
                                          const std::filesystem::path& rel, std::string* tried) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> candidates;
  if (!source_dir.empty()) candidates.push_back(fs::path(source_dir) / rel);
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / ".." / "share" / "weft" / share_subdir / rel);
  std::string list;
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c;
    list += (list.empty() ? "" : ", ") + c.string();
  }
  if (tried) *tried = list;
  return {};
}

}  // namespace weft
