#include "weft/core/run_limits.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "weft/core/error.h"
#include "weft/core/parallel.h"

namespace weft {

void work_starts(const RunLimits& limits) {
  if (limits.check_only) throw WorkWouldStart{};
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

double memory_budget_bytes(const RunLimits& l) {
  if (l.check_only && !(l.max_memory_bytes > 0)) return 0;
  return l.max_memory_bytes > 0 ? l.max_memory_bytes : available_memory_bytes();
}

void check_memory(const RunLimits& l, double bytes, const std::string& file,
                  const std::string& field, const std::string& what) {
  const double budget = memory_budget_bytes(l);
  if (budget > 0 && bytes > budget)
    throw Error(file, field,
                what + " needs about " + format_bytes(bytes) + " of memory, more than the " +
                    format_bytes(budget) +
                    (l.max_memory_bytes > 0 ? " allowed by --max-memory-gb"
                                            : " available (set the budget with --max-memory-gb)"));
}

void check_long_work(const RunLimits& l, double units, double seconds_per_unit, int threads,
                     const std::string& file, const std::string& field, const std::string& what,
                     const std::string& rate) {
  const auto cores = static_cast<unsigned>(thread_count(threads));
  const double seconds = units * seconds_per_unit / cores;
  const std::string basis = rate + ", " + std::to_string(cores) + (cores == 1 ? " core" : " cores");
  if (seconds > kLongWorkSeconds && !l.yes_long)
    throw Error(file, field,
                what + " would take at least " + format_seconds(seconds) + " (" + basis +
                    "); add --yes-long to run it anyway");
  if (seconds > kAnnouncedWorkSeconds && l.announce)
    l.announce(what + ": at least " + format_seconds(seconds) + " (" + basis + ")");
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

}  // namespace weft
