#pragma once
// Numbers and triples as the scene library's messages and notes print them: 6 significant digits.
#include <cstdio>
#include <string>

namespace weft::detail {

inline std::string format_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// "(x, y, z)": a vector or a colour.
inline std::string format_triple(double x, double y, double z) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", x, y, z);
  return buf;
}

}  // namespace weft::detail
