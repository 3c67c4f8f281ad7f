#pragma once
// Random byte edits of a valid file, for the fuzz-style tests of the loaders: each mutant must be
// taken or refused with a weft::Error, never crash or throw anything else.
#include <cstddef>
#include <string>

#include "weft/core/rng.h"

namespace weft::testing {

// 'text' with 1 to 4 edits drawn from 'rng': a byte replaced by any of the 256, a byte deleted, a
// random byte inserted, or a run of up to 16 bytes repeated.
inline std::string mutated(std::string text, Rng& rng) {
  const auto below = [&](size_t n) { return static_cast<size_t>(rng.uniform() * double(n)); };
  const int edits = 1 + static_cast<int>(below(4));
  for (int e = 0; e < edits && !text.empty(); ++e) {
    const size_t pos = below(text.size());
    const char byte = static_cast<char>(below(256));
    switch (below(4)) {
      case 0:
        text[pos] = byte;
        break;
      case 1:
        text.erase(pos, 1);
        break;
      case 2:
        text.insert(text.begin() + static_cast<std::ptrdiff_t>(pos), byte);
        break;
      default:
        text.insert(pos, text.substr(pos, 1 + below(16)));
    }
  }
  return text;
}

}  // namespace weft::testing
