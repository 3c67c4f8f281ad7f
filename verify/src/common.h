#pragma once
// Two small helpers that several of verify/src's files share (private to the library).
#include <chrono>
#include <cstdio>
#include <string>

namespace weft {

// A number with 'digits' significant digits (printf %g), for the report and messages.
inline std::string fmt(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace weft
