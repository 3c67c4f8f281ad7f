#include "weft/verify/suite.h"

#include <fstream>
#include <set>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/core/params.h"

namespace weft {
namespace {

namespace fs = std::filesystem;

// A suite file lists a few dozen fabrics; far more is a mistake, not a suite.
constexpr size_t kMaxSuiteFabrics = 256;
constexpr uint64_t kMaxSuiteFileBytes = 1 << 20;

bool safe_folder_name(const std::string& s) {
  if (s.empty() || s.size() > 100 || s == "." || s == "..") return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'))
      return false;
  return true;
}

// A path of the suite file, resolved against its folder; empty stays empty.
std::string resolve(const fs::path& base, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute()) return p;
  return (base / p).lexically_normal().string();
}

SuiteFabric read_fabric(ParamReader r, const fs::path& base) {
  SuiteFabric f;
  f.name = r.string("name");
  if (!safe_folder_name(f.name))
    throw Error(r.file(), r.field("name"),
                "'" + f.name + "' is not a folder name (letters, digits, '-', '_', '.')");
  f.measured = resolve(base, r.string("measured"));
  std::error_code ec;
  if (!fs::is_regular_file(f.measured, ec))
    throw Error(r.file(), r.field("measured"), "'" + f.measured + "' is not a readable file");
  // A fiber is a preset unless it names a file (as --fiber).
  f.fiber = r.string("fiber");
  const std::string as_path = resolve(base, f.fiber);
  if (fs::exists(as_path, ec)) f.fiber = as_path;
  f.weave = resolve(base, r.string("weave", ""));
  f.pattern = r.string("pattern", "");
  f.wif = resolve(base, r.string("wif", ""));
  if (r.has("colour_space")) f.colour_space = r.choice("colour_space", "srgb", {"srgb", "camera"});
  f.known = r.string("known");
  r.finish();
  return f;
}

}  // namespace

fs::path bundled_verify_suite() {
  std::string tried;
  const auto p = find_bundled_file("verify/data/suite.json", &tried);
  if (p.empty())
    throw Error("verify/data/suite.json", "--suite",
                "the bundled suite is not found (tried: " + tried + ")");
  return p;
}

VerifySuite read_verify_suite(const fs::path& file) {
  std::error_code ec;
  const auto bytes = fs::file_size(file, ec);
  if (ec) throw Error(file.string(), "", "cannot read the suite file");
  if (bytes > kMaxSuiteFileBytes)
    throw Error(file.string(), "",
                "is " + std::to_string(bytes) + " bytes; a suite file is at most " +
                    std::to_string(kMaxSuiteFileBytes));
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw Error(file.string(), "", "cannot read the suite file");
  const nlohmann::json j = parse_json(text.str(), file.string());
  ParamReader r(j, file.string(), "");
  VerifySuite s;
  s.file = file;
  s.title = r.string("title");
  const nlohmann::json& list = r.at("fabrics");
  if (!list.is_array() || list.empty())
    throw Error(file.string(), "fabrics", "is a non-empty array of fabrics");
  if (list.size() > kMaxSuiteFabrics)
    throw Error(file.string(), "fabrics",
                "lists " + std::to_string(list.size()) + " fabrics; at most " +
                    std::to_string(kMaxSuiteFabrics));
  std::set<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string path = "fabrics[" + std::to_string(i) + "]";
    s.fabrics.push_back(read_fabric(ParamReader(list[i], file.string(), path), file.parent_path()));
    if (!names.insert(s.fabrics.back().name).second)
      throw Error(file.string(), path + ".name", "'" + s.fabrics.back().name + "' is listed twice");
  }
  r.finish();
  return s;
}

VerifyRequest suite_request(const SuiteFabric& f, const VerifyRequest& base,
                            const fs::path& output) {
  VerifyRequest r;
  r.quality = base.quality;
  r.seed = base.seed;
  r.threads = base.threads;
  r.measured = f.measured;
  r.colour_space = f.colour_space;  // over the file's line, where the suite states it
  r.fiber = f.fiber;
  r.weave = f.weave;
  r.pattern = f.pattern;
  r.wif = f.wif;
  // Calibrated, each fabric's colour is its own measurement's reading: a colour is per fabric.
  r.colour_from = base.colour_from;
  r.output = (output / f.name).string();
  return r;
}

void check_suite_output(const fs::path& dir) {
  std::error_code ec;
  const fs::path target = fs::absolute(dir);
  if (!fs::is_directory(target.parent_path(), ec))
    throw Error(dir.string(), "-o", "the output's parent directory does not exist");
  if (!fs::exists(target, ec)) return;
  if (!fs::is_directory(target, ec))
    throw Error(dir.string(), "-o", "exists and is not a directory");
  if (fs::is_empty(target, ec)) return;
  std::ifstream m(target / "suite.json");
  const nlohmann::json j = nlohmann::json::parse(m, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("report", "") != "weft verify suite")
    throw Error(dir.string(), "-o",
                "exists and holds something other than an earlier weft verify suite; refusing "
                "to write into it");
}

}  // namespace weft
