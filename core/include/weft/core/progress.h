#pragma once
// Progress reporting: libraries call a callback, front ends draw. The callback may ask to stop
// (return false); long work then finishes the task in hand, keeps what is done and returns.
#include <cstdint>
#include <functional>
#include <string_view>

namespace weft {

struct ProgressUpdate {
  std::string_view stage;  // what is being done, e.g. "photons"
  uint64_t done = 0;       // units finished
  uint64_t total = 0;      // units in all (0 if unknown)
};

// Returns false to request cancellation.
using ProgressCallback = std::function<bool(const ProgressUpdate&)>;

// A callback that does nothing and never cancels.
inline ProgressCallback no_progress() {
  return [](const ProgressUpdate&) { return true; };
}

}  // namespace weft
