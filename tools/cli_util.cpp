#include "cli_util.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"

namespace weft::cli {
namespace {
std::atomic<bool> g_interrupted{false};  // set by the signal handler only
extern "C" void on_sigint(int) {
  g_interrupted.store(true);
}

}  // namespace

void install_interrupt_handler() {
  std::signal(SIGINT, on_sigint);
}
bool interrupted() {
  return g_interrupted.load();
}

ProgressCallback progress_bar(bool quiet) {
  if (run_limits().check_only) throw WorkWouldStart{};
  install_interrupt_handler();
  using Clock = std::chrono::steady_clock;
  struct State {
    Clock::time_point start = Clock::now();
    Clock::time_point last_draw{};
    std::string stage;
  };
  auto state = std::make_shared<State>();
  // A terminal gets one line redrawn in place; a log file or pipe gets plain lines, fewer of them,
  // so that a batch job's log is readable rather than one line of carriage returns.
  const bool terminal = isatty(fileno(stderr)) != 0;
  const auto period = terminal ? std::chrono::milliseconds(200) : std::chrono::milliseconds(10000);
  return [state, quiet, terminal, period](const ProgressUpdate& u) {
    if (!quiet) {
      const auto now = Clock::now();
      if (u.stage != state->stage) {
        state->stage = std::string(u.stage);
        state->start = now;
        state->last_draw = now;  // the first line comes one period into the stage
      }
      const bool finished = u.total > 0 && u.done >= u.total;
      if (finished || now - state->last_draw > period) {
        state->last_draw = now;
        const double elapsed = std::chrono::duration<double>(now - state->start).count();
        const std::string line = format_progress_line(u, elapsed);
        if (terminal)
          std::fprintf(stderr, "\r%-70s%s", line.c_str(), finished ? "\n" : "");
        else
          std::fprintf(stderr, "%s\n", line.c_str());
        std::fflush(stderr);
      }
    }
    return !g_interrupted.load();
  };
}

SceneDescription load_scene_reporting_warnings(const std::string& path,
                                               const std::vector<SceneOverride>& overrides,
                                               bool quiet) {
  SceneDescription desc = load_scene_description(path, overrides);
  for (const auto& w : desc.warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  if (quiet) return desc;
  // What the lights are, in the renderer's units (glTF photometric values were converted).
  for (const auto& n : desc.notes) std::fprintf(stderr, "weft: %s\n", n.c_str());
  for (const auto& l : describe_lights(desc.lights))
    std::fprintf(stderr, "weft: light: %s\n", l.c_str());
  return desc;
}

int report_render_outcome(const RenderOutcome& r, const std::string& what) {
  if (r.cancelled) {
    std::fprintf(stderr, "\nweft: %s cancelled; nothing was written\n", what.c_str());
    return 130;
  }
  if (r.nonfinite_samples)
    std::fprintf(stderr, "weft: warning: %llu non-finite samples were dropped\n",
                 static_cast<unsigned long long>(r.nonfinite_samples));
  return 0;
}

RunLimits& run_limits() {
  static RunLimits limits;  // set once by main() from the global options, before a command runs
  return limits;
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  double kb = 0;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0;
}

std::string format_bytes(double bytes) {
  char buf[32];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof buf, "%.1f GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.0f MB", std::ceil(bytes / 1e6));
  return buf;
}

std::string format_seconds(double s) {
  char buf[32];
  // Rounded up: these are lower bounds of time still to come.
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.0f s", std::ceil(s));
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%.0f min", std::ceil(s / 60));
  else if (s < 3 * 86400)
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  else if (s < 3 * 365 * 86400.0)
    std::snprintf(buf, sizeof buf, "%.1f days", s / 86400);
  else
    std::snprintf(buf, sizeof buf, "%.2g years", s / (365 * 86400.0));
  return buf;
}

double memory_budget_bytes() {
  const RunLimits& l = run_limits();
  if (l.check_only && !(l.max_memory_bytes > 0)) return 0;
  return l.max_memory_bytes > 0 ? l.max_memory_bytes : available_memory_bytes();
}

void check_memory(double bytes, const std::string& file, const std::string& field,
                  const std::string& what) {
  const RunLimits& l = run_limits();
  const double budget = memory_budget_bytes();
  if (budget > 0 && bytes > budget)
    throw Error(file, field,
                what + " needs about " + format_bytes(bytes) + " of memory, more than the " +
                    format_bytes(budget) +
                    (l.max_memory_bytes > 0 ? " allowed by --max-memory-gb"
                                            : " available (set the budget with --max-memory-gb)"));
}

void check_fiber_bake(const FiberTableBakeOptions& o, uint64_t bands,
                      const FiberBakeSource& source) {
  check_memory(fiber_table_bake_bytes(o), source.file, source.resolution_field,
               "a bake at resolution " + std::to_string(o.resolution));
  const double per_photon = fiber_bake_min_seconds_per_photon(o);
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.2g us per photon per core at least", per_photon * 1e6);
  check_long_work(static_cast<double>(o.photons_per_band) * static_cast<double>(bands), per_photon,
                  o.threads, source.file, source.photons_field,
                  std::to_string(o.photons_per_band) + " photons per band", rate);
}

void check_fabric_bake(const std::string& method, int resolution, uint64_t bins_traced,
                       std::optional<uint64_t> samples, int threads,
                       const std::string& samples_field) {
  if (method == "raytrace") {
    const uint64_t per_bin = samples.value_or(FabricRaytraceOptions{}.particles_per_bin);
    check_long_work(double(bins_traced) * double(per_bin), kMinSecondsPerFabricParticle, threads,
                    "", samples_field,
                    "a ray trace of " + std::to_string(bins_traced) + " incident bins x " +
                        std::to_string(per_bin) + " particles",
                    "0.25 us per particle per core at least");
  } else {
    const uint64_t bins = static_cast<uint64_t>(DirectionGrid{resolution}.bins());
    const uint64_t per_cell = samples.value_or(FabricSummationOptions{}.samples_per_cell);
    const bool visible = method == "summation-visible";
    check_long_work(double(bins * bins) * double(per_cell),
                    visible ? kMinSecondsPerVisiblePair : kMinSecondsPerPaperPair, threads, "",
                    samples_field,
                    "a " + method + " of " + std::to_string(bins * bins) + " cell pairs x " +
                        std::to_string(per_cell) + " direction pairs",
                    visible ? "5 us per direction pair per core at least"
                            : "0.1 us per direction pair per core at least");
  }
}

FiberTableResolver checked_fiber_table_resolver() {
  return fiber_table_resolver({}, [](const FiberTableBakeOptions& o, const FiberBakeSource& s) {
    check_fiber_bake(o, kNumBands, s);
  });
}

double render_bytes(int width, int height, bool preview, bool mask) {
  const double per_pixel = 3 * sizeof(float) + (preview ? 3 : 0) +
                           (mask ? sizeof(uint32_t) + 6 * sizeof(double) + sizeof(float) : 0);
  return double(width) * double(height) * per_pixel;
}

void check_long_work(double units, double seconds_per_unit, int threads, const std::string& file,
                     const std::string& field, const std::string& what, const std::string& rate) {
  const auto cores = static_cast<unsigned>(thread_count(threads));
  const double seconds = units * seconds_per_unit / cores;
  const std::string basis = rate + ", " + std::to_string(cores) + (cores == 1 ? " core" : " cores");
  if (seconds > kLongWorkSeconds && !run_limits().yes_long)
    throw Error(file, field,
                what + " would take at least " + format_seconds(seconds) + " (" + basis +
                    "); add --yes-long to run it anyway");
  if (seconds > kAnnouncedWorkSeconds && !run_limits().quiet)
    std::fprintf(stderr, "weft: %s: at least %s (%s)\n", what.c_str(),
                 format_seconds(seconds).c_str(), basis.c_str());
}

CLI::Validator seed_validator() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const bool digits = !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (s.size() > 1 && s[0] == '0'))
          return "a seed is a decimal integer in [0, 18446744073709551615], got '" + s + "'";
        errno = 0;
        std::strtoull(s.c_str(), nullptr, 10);
        if (errno == ERANGE) return "a seed must be below 2^64, got '" + s + "'";
        return "";
      },
      "SEED");
}

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

std::vector<NamedPath>& guarded_inputs_list() {
  static std::vector<NamedPath> inputs;
  return inputs;
}

}  // namespace

CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        const auto v = finite_number(s);
        if (!v || *v < lo || *v > hi)
          return "must be a finite number in [" + ParamReader::fmt(lo) + ", " +
                 ParamReader::fmt(hi) + "], got '" + s + "'";
        return "";
      },
      "NUMBER in [" + ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) + "]");
}

CLI::Validator non_empty() {
  return CLI::Validator(
      [](std::string& s) -> std::string { return s.empty() ? "must not be empty" : ""; }, "");
}

void validate_output_paths(const std::vector<NamedPath>& outputs,
                           const std::vector<NamedPath>& inputs,
                           const std::vector<NamedPath>& folders) {
  auto& seen = guarded_inputs_list();
  seen.insert(seen.end(), inputs.begin(), inputs.end());
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
    for (const auto& in : present)
      if (!folder.path.empty() && inside(in.path, folder.path)) refuse(folder, in, "holds");
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

const std::vector<NamedPath>& guarded_inputs() {
  return guarded_inputs_list();
}

std::vector<std::filesystem::path> scene_input_files(const std::string& scene,
                                                     const SceneDescription& d) {
  std::vector<std::filesystem::path> files{scene};
  files.insert(files.end(), d.files.begin(), d.files.end());
  auto add = [&](const MaterialBinding& b) {
    for (const char* key : {"file", "spec"}) {
      if (!b.params.contains(key) || !b.params[key].is_string()) continue;
      std::filesystem::path f = b.params[key].get<std::string>();
      std::error_code ec;
      if (f.is_relative() &&
          (std::string(key) == "file" || std::filesystem::exists(d.base_dir / f, ec)))
        f = d.base_dir / f;
      // A missing table is the renderer's error to report, with its field.
      if (std::filesystem::is_regular_file(f, ec)) files.push_back(f);
    }
  };
  for (const auto& [key, b] : d.materials) add(b);
  if (d.default_material) add(*d.default_material);
  return files;
}

std::vector<NamedPath> scene_inputs(const std::string& scene, const SceneDescription& d) {
  std::vector<NamedPath> out;
  for (const auto& f : scene_input_files(scene, d))
    out.push_back({f, out.empty() ? "scene description" : "scene's input"});
  // Where fiber_table_resolver keeps the tables it bakes for the scene (bake_cache.h).
  out.push_back({d.base_dir / ".weft-cache", "fiber-table bake cache"});
  return out;
}

std::vector<double> parse_range(const std::string& text, const std::string& option_name,
                                size_t max_count) {
  auto to_number = [&](const std::string& s) {
    if (const auto v = finite_number(s)) return *v;
    throw Error("", option_name, "'" + text + "' is not a number or range a:b:step");
  };
  std::vector<double> out;
  if (text.find(':') != std::string::npos) {
    std::vector<std::string> parts;
    std::stringstream ss(text);
    std::string p;
    while (std::getline(ss, p, ':')) parts.push_back(p);
    if (parts.size() != 3)
      throw Error("", option_name, "range must be a:b:step, got '" + text + "'");
    const double a = to_number(parts[0]), b = to_number(parts[1]), step = to_number(parts[2]);
    if (!(step > 0) || b < a) throw Error("", option_name, "range needs a <= b and step > 0");
    const double count = std::floor((b - a) / step + 1e-9) + 1;  // finite: a, b and step are
    if (count > static_cast<double>(max_count))
      throw Error("", option_name,
                  "range '" + text + "' has " + ParamReader::fmt(count) + " values, more than " +
                      std::to_string(max_count));
    const long n = static_cast<long>(count) - 1;
    for (long i = 0; i <= n; ++i) out.push_back(a + step * i);
    return out;
  }
  std::stringstream ss(text);
  std::string p;
  // getline drops a trailing empty item ("1,2,"): count the commas, refuse every empty item.
  const size_t items = static_cast<size_t>(std::count(text.begin(), text.end(), ',')) + 1;
  if (items > max_count)
    throw Error(
        "", option_name,
        "lists " + std::to_string(items) + " values, more than " + std::to_string(max_count));
  while (std::getline(ss, p, ',')) {
    if (p.empty()) break;
    out.push_back(to_number(p));
  }
  if (out.size() != items)
    throw Error("", option_name, "'" + text + "' has an empty item (a stray comma)");
  return out;
}

}  // namespace weft::cli
