#pragma once
// Text for the HTML pages Weft writes (verify's report, weft export's preview).
#include <string>

namespace weft {

// Text made safe for an HTML page.
inline std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o.push_back(c);
    }
  }
  return o;
}

}  // namespace weft
