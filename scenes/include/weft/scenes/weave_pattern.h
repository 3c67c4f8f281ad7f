#pragma once
// Weave patterns as interlacing matrices: for one repeat, which warp thread lies over which weft
// thread (pick). Built from a named pattern ("plain", "twill:N/M", "satin:N") or from a WIF
// draft (wif.h). Plain data; deterministic.
#include <cstdint>
#include <string>
#include <vector>

namespace weft {

struct Interlacing {
  int warps = 0;  // threads across the repeat (warp ends)
  int wefts = 0;  // picks in the repeat
  // warp_over[weft * warps + warp] = 1 where that warp thread lies over that pick (face side up).
  std::vector<uint8_t> warp_over;

  bool over(int warp, int weft) const {
    return warp_over[static_cast<size_t>(weft) * warps + warp] != 0;
  }
  // Threads that never interlace in the repeat (over every crossing thread, or under every one):
  // floating threads. Allowed, but a cloth with them falls apart without other binding.
  std::vector<int> floating_warps() const;
  std::vector<int> floating_wefts() const;
  // The same pattern seen after turning the cloth by 90 degrees: weft and warp swap roles
  // (the new warp i is the old pick i, lying over where the old pick lay over).
  Interlacing transposed() const;
  // One text row per pick ('X' where the warp is over, '.' where under): for messages and tests.
  std::string drawdown() const;
};

// Plain weave: warp i over pick j when i + j is even.
Interlacing plain_weave();
// N-up/M-down twill, diagonal step 1: warp i over pick j when (j - i) mod (N + M) < N.
Interlacing twill_weave(int up, int down);
// N-harness warp-faced satin with move number 'move' (0: the smallest valid one): warp i is under
// exactly one pick, (move * i) mod N, and over the others. A move number is valid when
// 1 < move < N - 1 and gcd(move, N) = 1; N = 4 and N = 6 have none and are errors.
Interlacing satin_weave(int n, int move = 0);
// "plain", "twill:N/M" or "satin:N" (optionally "satin:N/MOVE"). Error names 'field'.
Interlacing parse_weave_pattern(const std::string& spec, const std::string& field = "pattern");

}  // namespace weft
