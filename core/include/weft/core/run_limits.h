#pragma once
// The limits of one run of a command, carried in its request: the memory budget, the consent to
// long work, and whether the run only checks (weft slurm's check of the command it wraps). The
// checks a plan makes before any work read them here; there is no process-wide state.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"

namespace weft {

struct RunLimits {
  double max_memory_bytes = 0;  // 0: available_memory_bytes()
  bool yes_long = false;        // work estimated above kLongWorkSeconds may start
  // Every check is made, then work_starts throws WorkWouldStart where the work would start. The
  // memory available here is not the cluster's, so only an explicit max_memory_bytes is checked.
  bool check_only = false;
  // Where check_long_work's announcement of work above kAnnouncedWorkSeconds goes (a front end
  // prints it on stderr unless --quiet); empty: nowhere.
  std::function<void(const std::string&)> announce;
  // When set, validate_output_paths adds every input it is given here: weft slurm checks its
  // scripts against the inputs of the command it wraps.
  std::shared_ptr<std::vector<NamedPath>> guarded_inputs;
};

// Thrown by work_starts in a check-only run.
struct WorkWouldStart {};
// The point where a command's work starts, once every check has passed.
void work_starts(const RunLimits& limits);

// MemAvailable from /proc/meminfo (what can be allocated without swapping), else free pages.
double available_memory_bytes();
// The memory budget: max_memory_bytes, else the memory available; 0 (none) in a check-only run
// without an explicit budget.
double memory_budget_bytes(const RunLimits& limits);
// Error(file, field, ...) when an estimate of 'bytes' exceeds the memory budget: checked before
// allocating, so a run that cannot fit stops at once instead of dying of std::bad_alloc.
void check_memory(const RunLimits& limits, double bytes, const std::string& file,
                  const std::string& field, const std::string& what);

// Work estimated to take at least this long needs yes_long; above a minute the estimate is
// announced before the work starts.
inline constexpr double kLongWorkSeconds = 3600;
inline constexpr double kAnnouncedWorkSeconds = 60;
// Before long work, from a lower bound of its time: 'units' of work at 'seconds_per_unit' per
// core on the cores 'threads' gives (0: all). Announces "WHAT: at least T (BASIS)" above
// kAnnouncedWorkSeconds, and throws Error(file, field, ...) above kLongWorkSeconds unless
// yes_long. 'rate' names the rate the bound assumes ("0.05 us per path sample per core"): the
// basis announced is it with the cores.
void check_long_work(const RunLimits& limits, double units, double seconds_per_unit, int threads,
                     const std::string& file, const std::string& field, const std::string& what,
                     const std::string& rate);

// "2.3 GB", "95 s", "41 min", "3.2 h", "2.1 days" for messages (times rounded up).
std::string format_bytes(double bytes);
std::string format_seconds(double seconds);

}  // namespace weft
