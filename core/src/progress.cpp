#include "weft/core/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace weft {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const long long s = std::llround(seconds);
  char buf[48];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%02lld:%02lld", s / 60, s % 60);
  return buf;
}

std::string format_rate(double per_second, std::string_view unit) {
  const std::string u(unit.empty() ? std::string_view("units") : unit);
  if (!std::isfinite(per_second) || per_second < 0) return "-- " + u + "/s";
  // SI prefixes keep the figure to at most three digits before the point.
  static const char* const kPrefix[] = {"", "k ", "M ", "G ", "T "};
  int p = 0;
  double v = per_second;
  while (v >= 999.5 && p < 4) v /= 1000, ++p;
  char buf[64];
  std::snprintf(buf, sizeof buf, v < 9.995 && p > 0 ? "%.2f %s" : "%.3g %s", v, kPrefix[p]);
  return buf + u + "/s";
}

std::string format_progress_line(const ProgressUpdate& u, double elapsed_s) {
  const double rate = elapsed_s > 0 ? static_cast<double>(u.done) / elapsed_s : 0;
  std::string line(u.stage);
  if (u.total > 0) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "  %5.1f%%", 100.0 * static_cast<double>(u.done) / u.total);
    line += pct;
  }
  line += "  " + format_rate(rate, u.unit.empty() ? u.stage : u.unit);
  if (u.total > 0) {
    const double eta =
        rate > 0 ? static_cast<double>(u.total - std::min(u.done, u.total)) / rate : NAN;
    line += "  ETA " + format_duration(eta);
  }
  return line;
}

}  // namespace weft
