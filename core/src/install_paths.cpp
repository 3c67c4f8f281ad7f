#include "weft/core/install_paths.h"

#include <mutex>
#include <optional>
#include <system_error>

#ifndef WEFT_SOURCE_DIR
#define WEFT_SOURCE_DIR ""
#endif

namespace weft {
namespace {

struct InstalledRoot {
  std::mutex mutex;
  std::optional<std::filesystem::path> root;  // set_installed_data_root's
};
InstalledRoot& installed_root() {
  static InstalledRoot r;
  return r;
}

}  // namespace

void set_installed_data_root(const std::filesystem::path& root) {
  InstalledRoot& r = installed_root();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.root = root.lexically_normal();
}

std::vector<std::filesystem::path> bundled_data_roots() {
  namespace fs = std::filesystem;
  std::vector<fs::path> roots;
  std::error_code ec;
  // The installed tree first: an installed program must not read a source tree that happens to
  // still exist at the path it was built from (it may be newer or older than the install).
  {
    InstalledRoot& r = installed_root();
    const std::lock_guard<std::mutex> lock(r.mutex);
    if (r.root) roots.push_back(*r.root);
  }
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (roots.empty() && !ec)
    roots.push_back((exe.parent_path() / ".." / "share" / "weft").lexically_normal());
  if (!std::string(WEFT_SOURCE_DIR).empty()) roots.emplace_back(WEFT_SOURCE_DIR);
  return roots;
}

std::filesystem::path find_file_under(const std::vector<std::filesystem::path>& roots,
                                      const std::filesystem::path& rel, std::string* tried) {
  std::error_code ec;
  std::string list;
  for (const auto& root : roots) {
    const auto c = root / rel;
    if (std::filesystem::is_regular_file(c, ec)) return c;
    list += (list.empty() ? "" : ", ") + c.string();
  }
  if (tried) *tried = list;
  return {};
}

std::filesystem::path find_bundled_file(const std::filesystem::path& rel, std::string* tried) {
  return find_file_under(bundled_data_roots(), rel, tried);
}

}  // namespace weft
