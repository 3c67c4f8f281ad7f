#include "cli_util.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
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

std::optional<double> finite_number(const std::string& text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

void validate_output_paths(const std::vector<std::string>& outputs,
                           const std::vector<std::string>& inputs) {
  std::vector<NamedPath> out, in;
  for (const auto& p : outputs) out.push_back({p, "output"});
  for (const auto& p : inputs) in.push_back({p, "input"});
  check_output_paths(out, in);
}

std::vector<double> parse_range(const std::string& text, const std::string& option_name) {
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
    const long n = std::lround(std::floor((b - a) / step + 1e-9));
    for (long i = 0; i <= n; ++i) out.push_back(a + step * i);
    return out;
  }
  std::stringstream ss(text);
  std::string p;
  while (std::getline(ss, p, ',')) out.push_back(to_number(p));
  if (out.empty()) throw Error("", option_name, "empty list");
  return out;
}

}  // namespace weft::cli
