#include "cli_util.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "weft/core/error.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/description.h"

namespace weft::cli {
namespace {
std::atomic<bool> g_interrupted{false};  // set by the signal handler only
extern "C" void on_sigint(int) {
  g_interrupted.store(true);
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const long s = std::lround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
  return buf;
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
  return [state, quiet](const ProgressUpdate& u) {
    if (!quiet) {
      const auto now = Clock::now();
      if (u.stage != state->stage) {
        state->stage = std::string(u.stage);
        state->start = now;
      }
      const bool finished = u.total > 0 && u.done >= u.total;
      if (finished || now - state->last_draw > std::chrono::milliseconds(200)) {
        state->last_draw = now;
        const double elapsed = std::chrono::duration<double>(now - state->start).count();
        const double rate = elapsed > 0 ? static_cast<double>(u.done) / elapsed : 0;
        const double frac = u.total > 0 ? static_cast<double>(u.done) / u.total : 0;
        const double eta = rate > 0 && u.total > 0 ? (u.total - u.done) / rate : NAN;
        std::fprintf(stderr, "\r%-10s %5.1f%%  %10.4g/s  ETA %s   ", state->stage.c_str(),
                     100 * frac, rate, format_duration(eta).c_str());
        if (finished) std::fprintf(stderr, "\n");
        std::fflush(stderr);
      }
    }
    return !g_interrupted.load();
  };
}

SceneDescription load_scene_reporting_warnings(const std::string& path) {
  SceneDescription desc = load_scene_description(path);
  for (const auto& w : desc.warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
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
  namespace fs = std::filesystem;
  auto canonical = [](const std::string& p) {
    std::error_code ec;
    const fs::path c = fs::weakly_canonical(fs::absolute(p), ec);
    return ec ? fs::absolute(p).lexically_normal() : c;
  };
  std::vector<std::pair<fs::path, std::string>> seen;
  for (const auto& in : inputs) {
    std::error_code ec;
    if (!in.empty() && fs::exists(in, ec)) seen.emplace_back(canonical(in), "input " + in);
  }
  for (const auto& out : outputs) {
    if (out.empty()) continue;
    const fs::path c = canonical(out);
    if (!fs::is_directory(c.parent_path())) throw Error(out, "", "output directory does not exist");
    if (fs::is_directory(c)) throw Error(out, "", "is a directory, not a file");
    for (const auto& [p, what] : seen)
      if (p == c) throw Error(out, "", "is also the " + what + ": refusing to overwrite it");
    seen.emplace_back(c, "output " + out);
  }
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
