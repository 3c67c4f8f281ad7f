#include "weft/core/output_guard.h"

#include "weft/core/error.h"

namespace weft {
namespace {

namespace fs = std::filesystem;

// The path as the file system resolves it: symbolic links followed; a path not there yet as its
// resolved folder and its name.
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  const fs::path c = fs::weakly_canonical(fs::absolute(p, ec), ec);
  return ec ? fs::absolute(p).lexically_normal() : c;
}

// 'p' is 'folder' or lies inside it, once both are resolved.
bool inside(const fs::path& p, const fs::path& folder) {
  const fs::path rel = resolved(p).lexically_relative(resolved(folder));
  return !rel.empty() && *rel.begin() != "..";
}

// 'out' is the existing file 'in' (same device and inode, through any link) or will be written
// where 'in' lies.
bool same_file(const fs::path& out, const fs::path& in) {
  std::error_code ec;
  if (fs::exists(out, ec) && fs::equivalent(out, in, ec) && !ec) return true;
  return resolved(out) == resolved(in);
}

}  // namespace

void validate_output_paths(const RunLimits& limits, const std::vector<NamedPath>& outputs,
                           const std::vector<NamedPath>& inputs,
                           const std::vector<NamedPath>& folders) {
  if (limits.guarded_inputs)
    limits.guarded_inputs->insert(limits.guarded_inputs->end(), inputs.begin(), inputs.end());
  std::vector<NamedPath> present;  // inputs that are files or folders here (not preset names)
  for (const auto& in : inputs) {
    std::error_code ec;
    if (!in.path.empty() && fs::exists(in.path, ec)) present.push_back(in);
  }
  auto refuse = [](const NamedPath& out, const NamedPath& in, const std::string& how) {
    throw Error(out.path.string(), out.what,
                how + " the " + in.what + " '" + in.path.string() + "': refusing to " +
                    (how == "holds" ? "replace it" : "overwrite it"));
  };
  for (const auto& out : outputs) {
    if (out.path.empty()) continue;
    for (const auto& in : present) {
      std::error_code ec;
      if (same_file(out.path, in.path)) refuse(out, in, "is also");
      if (fs::is_directory(in.path, ec) && inside(out.path, in.path)) refuse(out, in, "lies in");
    }
  }
  for (const auto& folder : folders)
    for (const auto& in : present) {
      if (folder.path.empty()) continue;
      // A folder output named as an input file (a hard link has no folder to lie in).
      if (same_file(folder.path, in.path)) refuse(folder, in, "is also");
      if (inside(in.path, folder.path)) refuse(folder, in, "holds");
    }
  // Each in an existing directory, not a directory, no two the same file.
  check_output_paths(outputs, {});
}

std::vector<NamedPath> json_named_files(const nlohmann::json& j, const std::string& what) {
  std::vector<NamedPath> out;
  auto add = [&](const nlohmann::json& v) {
    for (auto& f : json_named_files(v, what)) out.push_back(std::move(f));
  };
  if (j.is_string()) {
    const std::string& s = j.get_ref<const std::string&>();
    std::error_code ec;
    if (!s.empty() && s.size() < 4096 && fs::exists(s, ec)) out.push_back({s, what});
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) add(it.key()), add(it.value());
  } else if (j.is_array()) {
    for (const auto& v : j) add(v);
  }
  return out;
}

}  // namespace weft
