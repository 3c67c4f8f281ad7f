#pragma once
// Small helpers that several of verify/src's files share (private to the library).
#include <cstdio>
#include <sstream>
#include <string>

#include "weft/core/clock.h"
#include "weft/core/html.h"  // html_escape

namespace weft {

// A number with 'digits' significant digits (printf %g), for the report and messages.
inline std::string fmt(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

struct VerifyReport;
// The page's verdict section, which leads it (report_html_verdict.cpp).
void html_verdict(std::ostringstream& h, const VerifyReport& r);

}  // namespace weft
