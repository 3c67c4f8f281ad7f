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
#include <sstream>
#include <thread>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
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

SceneDescription load_scene_reporting_warnings(const std::string& path) {
  return load_scene_reporting_warnings(path, {});
}

SceneDescription load_scene_reporting_warnings(const std::string& path,
                                               const std::vector<SceneOverride>& overrides) {
  SceneDescription desc = load_scene_description(path, overrides);
  for (const auto& w : desc.warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
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

void check_memory(double bytes, const std::string& file, const std::string& field,
                  const std::string& what) {
  const RunLimits& l = run_limits();
  const double budget = l.max_memory_bytes > 0 ? l.max_memory_bytes : available_memory_bytes();
  if (budget > 0 && bytes > budget)
    throw Error(file, field,
                what + " needs about " + format_bytes(bytes) + " of memory, more than the " +
                    format_bytes(budget) +
                    (l.max_memory_bytes > 0 ? " allowed by --max-memory-gb"
                                            : " available (set the budget with --max-memory-gb)"));
}

double render_bytes(int width, int height, bool preview, bool mask) {
  const double per_pixel = 3 * sizeof(float) + (preview ? 3 : 0) +
                           (mask ? sizeof(uint32_t) + 6 * sizeof(double) + sizeof(float) : 0);
  return double(width) * double(height) * per_pixel;
}

void check_long_work(double units, double seconds_per_unit, int threads, const std::string& file,
                     const std::string& field, const std::string& what, const std::string& rate) {
  const unsigned cores = threads > 0 ? static_cast<unsigned>(threads)
                                     : std::max(1u, std::thread::hardware_concurrency());
  const double seconds = units * seconds_per_unit / cores;
  const std::string basis = rate + ", " + std::to_string(cores) + (cores == 1 ? " core" : " cores");
  if (seconds > kLongWorkSeconds && !run_limits().yes_long)
    throw Error(file, field,
                what + " would take at least " + format_seconds(seconds) + " (" + basis +
                    "); add --yes-long to run it anyway");
  if (seconds > kAnnouncedWorkSeconds)
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

void validate_output_paths(const std::vector<std::string>& outputs,
                           const std::vector<std::string>& inputs) {
  std::vector<NamedPath> out, in;
  for (const auto& p : outputs) out.push_back({p, "output"});
  for (const auto& p : inputs) in.push_back({p, "input"});
  check_output_paths(out, in);
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
