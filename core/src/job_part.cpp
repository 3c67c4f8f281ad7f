#include "weft/core/job_part.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <set>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/params.h"

namespace weft {
namespace {

constexpr const char* kMagic = "WEFT-PART 1";
// A header is a few kilobytes; a bound keeps a corrupt file from asking for gigabytes.
constexpr size_t kMaxHeaderBytes = size_t{1} << 24;

static_assert(std::endian::native == std::endian::little, "part files are little-endian");

}  // namespace

Shard parse_shard(const std::string& text, const std::string& option_name) {
  const auto slash = text.find('/');
  auto whole_number = [&](const std::string& s) -> uint64_t {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
      throw Error("", option_name, "'" + text + "' is not K/N (0 <= K < N)");
    return std::stoull(s);
  };
  if (slash == std::string::npos) throw Error("", option_name, "'" + text + "' is not K/N");
  const uint64_t k = whole_number(text.substr(0, slash)), n = whole_number(text.substr(slash + 1));
  if (n < 1 || k >= n || n > kMaxShards)
    throw Error("", option_name,
                "'" + text + "' needs 0 <= K < N <= " + std::to_string(kMaxShards));
  return {static_cast<uint32_t>(k), static_cast<uint32_t>(n)};
}

UnitRange shard_units(uint64_t units, Shard s) {
  return {units * s.index / s.count, units * (s.index + 1) / s.count};
}

bool JobPart::same_job(const JobPart& o) const {
  return command == o.command && job == o.job && units_total == o.units_total &&
         shard.count == o.shard.count;
}

void push_u64(std::vector<double>& v, uint64_t x) {
  v.push_back(std::bit_cast<double>(x));
}
uint64_t as_u64(double d) {
  return std::bit_cast<uint64_t>(d);
}

void write_job_part(const std::filesystem::path& path, const JobPart& p) {
  nlohmann::json units = nlohmann::json::array(), sizes = nlohmann::json::array();
  for (const auto& [u, v] : p.units) units.push_back(u), sizes.push_back(v.size());
  const nlohmann::json header = {{"command", p.command},
                                 {"job", p.job},
                                 {"units_total", p.units_total},
                                 {"shard", p.shard.index},
                                 {"shards", p.shard.count},
                                 {"checkpoint", p.checkpoint},
                                 {"extra", p.extra},
                                 {"units", units},
                                 {"unit_doubles", sizes}};
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << kMagic << "\n" << header.dump() << "\n";
    for (const auto& [u, v] : p.units)
      out.write(reinterpret_cast<const char*>(v.data()),
                static_cast<std::streamsize>(v.size() * sizeof(double)));
    out.close();
    if (!out) throw Error(path.string(), "", "write failed");
  });
}

JobPart read_job_part(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(file, "", "cannot open");
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(file, "", "cannot read its size");
  std::string magic;
  std::getline(in, magic);
  if (magic != kMagic)
    throw Error(file, "", "not a weft part or checkpoint (no '" + std::string(kMagic) + "' line)");
  std::string line;
  line.reserve(4096);
  char c;
  while (in.get(c) && c != '\n') {
    line.push_back(c);
    if (line.size() > kMaxHeaderBytes) throw Error(file, "header", "longer than 16 MiB");
  }
  if (!in) throw Error(file, "header", "truncated");
  JobPart p;
  try {
    const auto h = parse_json(line, file);
    ParamReader r(h, file, "");
    p.command = r.string("command");
    p.job = r.at("job");
    // The counts before anything is sized or looped over by them.
    p.units_total = r.count("units_total", 0, kMaxJobUnits);
    p.shard.count = static_cast<uint32_t>(r.count("shards", 1, kMaxShards));
    p.shard.index = static_cast<uint32_t>(r.count("shard", 0, p.shard.count - 1));
    p.checkpoint = h.at("checkpoint").get<bool>();
    p.extra = r.at("extra");
    // A unit is listed once at most: a longer list is refused before it is converted.
    const auto units = r.counts("units", p.units_total, 0, p.units_total - 1);
    const auto sizes = r.counts("unit_doubles", p.units_total, 0, size / sizeof(double));
    if (units.size() != sizes.size()) throw Error(file, "units", "does not match unit_doubles");
    uint64_t doubles = 0;
    for (size_t i = 0; i < units.size(); ++i) {
      doubles += sizes[i];
    }
    const uint64_t payload_at = static_cast<uint64_t>(in.tellg());
    if (doubles > size / sizeof(double) || payload_at + doubles * sizeof(double) != size)
      throw Error(file, "", "truncated or padded: the payload does not match its header");
    for (size_t i = 0; i < units.size(); ++i) {
      std::vector<double> v(sizes[i]);
      in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(sizes[i] * 8));
      if (!p.units.emplace(units[i], std::move(v)).second)
        throw Error(file, "units", "unit " + std::to_string(units[i]) + " appears twice");
    }
    if (!in) throw Error(file, "", "truncated payload");
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, "header", e.what());
  }
  return p;
}

nlohmann::json input_file_hashes(const std::vector<std::filesystem::path>& files) {
  nlohmann::json out = nlohmann::json::object();
  std::vector<char> buf(size_t{1} << 20);
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    if (!in) throw Error(f.string(), "", "cannot read this input to identify the job");
    uint64_t h = kFnv1a64Basis;
    while (in) {
      in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
      h = fnv1a64(reinterpret_cast<const unsigned char*>(buf.data()),
                  static_cast<size_t>(in.gcount()), h);
    }
    if (in.bad()) throw Error(f.string(), "", "read failed while identifying the job");
    out[f.string()] = hex64(h);
  }
  return out;
}

std::vector<std::string> changed_job_inputs(const JobPart& all) {
  std::vector<std::string> changed;
  auto check = [&](const nlohmann::json& files) {
    if (!files.is_object()) return;
    for (const auto& [file, then] : files.items()) {
      std::error_code ec;
      if (!then.is_string() || !std::filesystem::is_regular_file(file, ec)) continue;
      const std::string now = input_file_hashes({file})[file].get<std::string>();
      if (now != then.get<std::string>())
        changed.push_back(file + " (checksum " + then.get<std::string>() + " in the parts, " + now +
                          " now)");
    }
  };
  if (all.job.contains("inputs")) check(all.job["inputs"]);
  if (all.extra.contains(kPartInputFilesKey)) check(all.extra[kPartInputFilesKey]);
  return changed;
}

std::string job_difference(const JobPart& then, const JobPart& now) {
  if (then.command != now.command)
    return "it is of `weft " + then.command + "`, not `weft " + now.command + "`";
  const auto& a = then.job;
  const auto& b = now.job;
  if (a.contains("inputs") && b.contains("inputs") && a["inputs"] != b["inputs"]) {
    for (const auto& [file, hash] : b["inputs"].items())
      if (a["inputs"].contains(file) && a["inputs"][file] != hash)
        return "the content of " + file + " differs";
    return "the job reads other input files (" + b["inputs"].dump() + " against " +
           a["inputs"].dump() + ")";
  }
  for (const auto& [key, value] : b.items())
    if (!a.contains(key) || a[key] != value) return "setting '" + key + "' differs";
  for (const auto& [key, value] : a.items())
    if (!b.contains(key)) return "setting '" + key + "' differs";
  if (then.units_total != now.units_total) return "the number of units differs";
  if (then.shard.count != now.shard.count) return "the shard count differs";
  return "";
}

std::filesystem::path checkpoint_path(const std::filesystem::path& output) {
  const auto name = "." + output.filename().string() + ".weft-checkpoint";
  return output.has_parent_path() ? output.parent_path() / name : std::filesystem::path(name);
}

std::optional<JobPart> load_checkpoint(const std::filesystem::path& output, const JobPart& job,
                                       bool resume, std::vector<std::string>& warnings) {
  const auto path = checkpoint_path(output);
  if (!resume || !std::filesystem::exists(path)) return std::nullopt;
  JobPart p;
  try {
    p = read_job_part(path);
  } catch (const Error&) {
    // Written atomically, so a bad checkpoint was damaged afterwards: start over.
    warnings.push_back(path.string() + " is unreadable; starting afresh");
    return std::nullopt;
  }
  if (!p.checkpoint || !p.same_job(job) || p.shard.index != job.shard.index) {
    std::string why = job_difference(p, job);
    if (why.empty()) why = p.checkpoint ? "the shard differs" : "it is not a checkpoint";
    throw Error(
        path.string(), "",
        "is the checkpoint of another job (" + why + "): remove it or run without --resume");
  }
  return p;
}

JobPart merge_job_parts(const std::vector<std::filesystem::path>& paths) {
  if (paths.empty()) throw Error("", "parts", "no parts given");
  JobPart all;
  std::map<uint64_t, std::string> owner;
  std::set<uint32_t> shards_seen;
  for (size_t i = 0; i < paths.size(); ++i) {
    JobPart p = read_job_part(paths[i]);
    const std::string file = paths[i].string();
    if (p.checkpoint)
      throw Error(file, "", "is a checkpoint of an unfinished run, not a finished part");
    if (i == 0) {
      all.command = p.command, all.job = p.job, all.units_total = p.units_total;
      all.shard = {0, p.shard.count};
      all.extra = p.extra;
    } else if (!p.same_job(all)) {
      throw Error(
          file, "job",
          "belongs to another job than " + paths[0].string() + " (" + job_difference(all, p) + ")");
    } else if (p.extra.contains(kPartInputFilesKey) && p.extra[kPartInputFilesKey].is_object()) {
      nlohmann::json& files = all.extra[kPartInputFilesKey];
      if (!files.is_object()) files = nlohmann::json::object();
      files.update(p.extra[kPartInputFilesKey]);
    }
    if (!shards_seen.insert(p.shard.index).second)
      throw Error(file, "shard",
                  "shard " + std::to_string(p.shard.index) + "/" + std::to_string(p.shard.count) +
                      " is given twice");
    const UnitRange r = shard_units(p.units_total, p.shard);
    if (p.units.size() != r.last - r.first)
      throw Error(file, "units", "the part does not hold every unit of its shard");
    for (auto& [u, v] : p.units) {
      if (u < r.first || u >= r.last)
        throw Error(file, "units", "unit " + std::to_string(u) + " is not of its shard");
      if (const auto it = owner.find(u); it != owner.end())
        throw Error(file, "units", "unit " + std::to_string(u) + " is also in " + it->second);
      owner.emplace(u, file);
      all.units.emplace(u, std::move(v));
    }
  }
  // The first few missing shards by name, the rest counted (up to kMaxShards of them).
  std::string missing;
  uint32_t more = 0;
  for (uint32_t k = 0; k < all.shard.count; ++k) {
    const UnitRange r = shard_units(all.units_total, {k, all.shard.count});
    if (shards_seen.count(k) || r.last == r.first) continue;
    if (missing.size() < 80)
      missing +=
          (missing.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(all.shard.count);
    else
      ++more;
  }
  if (more > 0) missing += " and " + std::to_string(more) + " more";
  if (!missing.empty()) throw Error("", "parts", "incomplete: missing shard " + missing);
  return all;
}

}  // namespace weft
