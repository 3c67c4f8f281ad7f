#pragma once
// Progress reporting: libraries call a callback, front ends draw. The callback may ask to stop
// (return false); long work then finishes the task in hand, keeps what is done and returns.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace weft {

struct ProgressUpdate {
  std::string_view stage;  // what is being done, e.g. "photons"
  uint64_t done = 0;       // units finished
  uint64_t total = 0;      // units in all (0 if unknown)
  std::string_view unit;   // what 'done' counts, e.g. "samples" (empty: the stage names it)

  ProgressUpdate() = default;
  // The unit is optional so that a stage that names its unit ("photons") needs none.
  ProgressUpdate(std::string_view stage_, uint64_t done_, uint64_t total_,
                 std::string_view unit_ = {})
      : stage(stage_), done(done_), total(total_), unit(unit_) {}
};

// Returns false to request cancellation.
using ProgressCallback = std::function<bool(const ProgressUpdate&)>;

// A callback that does nothing and never cancels.
inline ProgressCallback no_progress() {
  return [](const ProgressUpdate&) { return true; };
}

// "1:02:03" at an hour or more, "02:03" below, "--:--" when unknown (negative or not finite).
std::string format_duration(double seconds);
// A rate with an SI prefix and its unit: "1.23 M samples/s", "512 photons/s".
std::string format_rate(double per_second, std::string_view unit);
// One line of progress, as a log shows it (no carriage return, no newline):
//   "render  45.0%  1.23 M samples/s  ETA 00:12"
// 'elapsed_s' is the time since the stage began. The percent and the ETA are left out when the
// total is unknown; the ETA is "--:--" before any unit is done.
std::string format_progress_line(const ProgressUpdate& u, double elapsed_s);

}  // namespace weft
