#include "weft/core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <fstream>
#include <system_error>

#include "weft/core/error.h"

namespace weft {

namespace {
std::filesystem::path temporary_sibling(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) throw Error(path.string(), "", "output directory does not exist");
  // A name of its own per process and call, so that writers of one path never share a temporary;
  // the extension last: writers such as OpenImageIO choose the format by it.
  static std::atomic<uint64_t> calls{0};
  return parent / (".tmp-" + path.stem().string() + "-" + std::to_string(::getpid()) + "-" +
                   std::to_string(calls.fetch_add(1)) + "-partial" + path.extension().string());
}
}  // namespace

void write_all_atomically(
    const std::vector<std::pair<std::filesystem::path, FileWriter>>& outputs) {
  namespace fs = std::filesystem;
  std::vector<fs::path> tmps;
  auto remove_all = [&] {
    std::error_code ec;
    for (const auto& t : tmps) fs::remove(t, ec);
  };
  try {
    for (const auto& [path, write] : outputs) {
      tmps.push_back(temporary_sibling(path));
      write(tmps.back());
    }
  } catch (...) {
    remove_all();
    throw;
  }
  for (size_t i = 0; i < outputs.size(); ++i) {
    std::error_code ec;
    fs::rename(tmps[i], outputs[i].first, ec);
    if (ec) {
      remove_all();
      throw Error(outputs[i].first.string(), "", "cannot move the finished output into place");
    }
  }
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  const fs::path tmp = temporary_sibling(path);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(path.string(), "", "cannot move the finished output into place");
  }
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw Error(path.string(), "", "write failed");
  });
}

void check_output_paths(const std::vector<NamedPath>& outputs,
                        const std::vector<NamedPath>& inputs) {
  namespace fs = std::filesystem;
  auto canonical = [](const fs::path& p) {
    std::error_code ec;
    const fs::path c = fs::weakly_canonical(fs::absolute(p, ec), ec);
    return ec ? fs::absolute(p).lexically_normal() : c;
  };
  std::vector<std::pair<fs::path, std::string>> seen;
  for (const auto& in : inputs) {
    std::error_code ec;
    if (!in.path.empty() && fs::exists(in.path, ec)) seen.emplace_back(canonical(in.path), in.what);
  }
  for (const auto& out : outputs) {
    if (out.path.empty()) continue;
    const fs::path c = canonical(out.path);
    std::error_code ec;
    if (!fs::is_directory(c.parent_path(), ec))
      throw Error(out.path.string(), out.what, "output directory does not exist");
    if (fs::is_directory(c, ec)) throw Error(out.path.string(), out.what, "is a directory, not a file");
    for (const auto& [p, what] : seen)
      if (p == c)
        throw Error(out.path.string(), out.what,
                    "is also the " + what + " file: refusing to overwrite it");
    seen.emplace_back(c, out.what);
  }
}

}  // namespace weft
