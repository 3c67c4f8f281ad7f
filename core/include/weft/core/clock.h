#pragma once
// Elapsed wall-clock time, the one way the project measures it for the figures it reports (stage
// times, rates, ETAs).
#include <chrono>

namespace weft {

using SteadyClock = std::chrono::steady_clock;

inline double seconds_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double>(SteadyClock::now() - t0).count();
}

}  // namespace weft
