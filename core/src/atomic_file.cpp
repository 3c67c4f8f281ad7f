#include "weft/core/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <fstream>
#include <limits>
#include <system_error>

#include "weft/core/error.h"

namespace weft {

namespace {

constexpr const char* kTmpPrefix = ".tmp-";
constexpr const char* kTmpSuffix = "-partial";

// This host's name as it goes into a temporary's name: no '@' or '/' (the name is parsed back).
std::string host_tag() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown-host";
  std::string h(buf);
  for (char& c : h)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-')) c = '_';
  return h.empty() ? "unknown-host" : h;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 18 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

size_t remove_stale_temporaries(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const std::string head = kTmpPrefix + path.stem().string() + "-";
  const std::string tail = kTmpSuffix + path.extension().string();
  const std::string host = host_tag();
  size_t removed = 0;
  std::error_code ec;
  fs::directory_iterator it(parent, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= head.size() + tail.size() || name.compare(0, head.size(), head) != 0 ||
        name.compare(name.size() - tail.size(), tail.size(), tail) != 0)
      continue;
    // The middle is "<host>@<pid>-<n>"; anything else is not ours to remove.
    const std::string mid = name.substr(head.size(), name.size() - head.size() - tail.size());
    const auto at = mid.rfind('@'), dash = mid.rfind('-');
    if (at == std::string::npos || dash == std::string::npos || dash < at) continue;
    const std::string pid_text = mid.substr(at + 1, dash - at - 1);
    if (mid.substr(0, at) != host || !all_digits(pid_text) || !all_digits(mid.substr(dash + 1)))
      continue;
    const long long pid = std::stoll(pid_text);
    if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours
    std::error_code rm;
    if (fs::remove_all(it->path(), rm) > 0 && !rm) ++removed;
  }
  return removed;
}

std::filesystem::path temporary_sibling(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) throw Error(path.string(), "", "output directory does not exist");
  remove_stale_temporaries(path);
  static std::atomic<uint64_t> calls{0};
  return parent /
         (kTmpPrefix + path.stem().string() + "-" + host_tag() + "@" + std::to_string(::getpid()) +
          "-" + std::to_string(calls.fetch_add(1)) + kTmpSuffix + path.extension().string());
}

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

void write_bytes_atomically(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
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
    if (fs::is_directory(c, ec))
      throw Error(out.path.string(), out.what, "is a directory, not a file");
    for (const auto& [p, what] : seen)
      if (p == c)
        throw Error(out.path.string(), out.what,
                    "is also the " + what + " file: refusing to overwrite it");
    seen.emplace_back(c, out.what);
  }
}

}  // namespace weft
