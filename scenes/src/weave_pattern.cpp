#include "weft/scenes/weave_pattern.h"

#include <charconv>
#include <numeric>

#include "weft/core/error.h"

namespace weft {
namespace {

// Largest repeat a named pattern may have: far beyond any loom, small enough to allocate.
constexpr int kMaxNamedRepeat = 1024;

Interlacing blank(int warps, int wefts) {
  Interlacing m;
  m.warps = warps;
  m.wefts = wefts;
  m.warp_over.assign(static_cast<size_t>(warps) * wefts, 0);
  return m;
}

int parse_int(const std::string& text, const std::string& field, const std::string& spec) {
  int v = 0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (text.empty() || r.ec != std::errc() || r.ptr != end)
    throw Error("", field, "'" + spec + "': '" + text + "' is not an integer");
  return v;
}

}  // namespace

std::vector<int> Interlacing::floating_warps() const {
  std::vector<int> out;
  for (int i = 0; i < warps; ++i) {
    bool any_over = false, any_under = false;
    for (int j = 0; j < wefts; ++j) (over(i, j) ? any_over : any_under) = true;
    if (!(any_over && any_under)) out.push_back(i);
  }
  return out;
}

std::vector<int> Interlacing::floating_wefts() const {
  // Pick j is warp j of the transpose, whose crossings are this one's, each side swapped: all on
  // one side there exactly when all on one side here.
  return transposed().floating_warps();
}

Interlacing Interlacing::transposed() const {
  Interlacing t = blank(wefts, warps);
  // New warp j (old pick j) is over new pick i (old warp i) where the old warp was under.
  for (int i = 0; i < warps; ++i)
    for (int j = 0; j < wefts; ++j)
      t.warp_over[static_cast<size_t>(i) * t.warps + j] = over(i, j) ? 0 : 1;
  return t;
}

std::string Interlacing::drawdown() const {
  std::string s;
  for (int j = 0; j < wefts; ++j) {
    for (int i = 0; i < warps; ++i) s += over(i, j) ? 'X' : '.';
    s += '\n';
  }
  return s;
}

Interlacing plain_weave() {
  return twill_weave(1, 1);
}

Interlacing twill_weave(int up, int down) {
  if (up < 1 || down < 1 || up + down > kMaxNamedRepeat)
    throw Error("", "pattern",
                "twill N/M needs N >= 1, M >= 1 and N + M <= " + std::to_string(kMaxNamedRepeat));
  const int r = up + down;
  Interlacing m = blank(r, r);
  for (int j = 0; j < r; ++j)
    for (int i = 0; i < r; ++i)
      m.warp_over[static_cast<size_t>(j) * r + i] = ((j - i + r) % r) < up;
  return m;
}

Interlacing satin_weave(int n, int move) {
  if (n < 5 || n > kMaxNamedRepeat)
    throw Error("", "pattern",
                "satin needs N in [5, " + std::to_string(kMaxNamedRepeat) +
                    "] (N = " + std::to_string(n) + ")");
  auto valid = [n](int m) { return m > 1 && m < n - 1 && std::gcd(m, n) == 1; };
  if (move == 0) {
    for (int m = 2; m < n - 1 && move == 0; ++m)
      if (valid(m)) move = m;
    if (move == 0)
      throw Error("", "pattern",
                  "no " + std::to_string(n) +
                      "-harness satin exists: no move number 1 < m < N - 1 is coprime with N");
  } else if (!valid(move)) {
    throw Error("", "pattern",
                "move number " + std::to_string(move) + " is not valid for a " + std::to_string(n) +
                    "-harness satin (needs 1 < m < N - 1 and gcd(m, N) = 1)");
  }
  Interlacing s = blank(n, n);
  std::fill(s.warp_over.begin(), s.warp_over.end(), 1);
  for (int i = 0; i < n; ++i) s.warp_over[static_cast<size_t>((move * i) % n) * n + i] = 0;
  return s;
}

Interlacing parse_weave_pattern(const std::string& spec, const std::string& field) {
  try {
    if (spec == "plain") return plain_weave();
    const auto colon = spec.find(':');
    const std::string kind = spec.substr(0, colon);
    const std::string args = colon == std::string::npos ? "" : spec.substr(colon + 1);
    const auto slash = args.find('/');
    if (kind == "twill" && colon != std::string::npos && slash != std::string::npos)
      return twill_weave(parse_int(args.substr(0, slash), field, spec),
                         parse_int(args.substr(slash + 1), field, spec));
    if (kind == "satin" && colon != std::string::npos) {
      if (slash == std::string::npos) return satin_weave(parse_int(args, field, spec));
      return satin_weave(parse_int(args.substr(0, slash), field, spec),
                         parse_int(args.substr(slash + 1), field, spec));
    }
  } catch (const Error& e) {
    // Re-issue under the caller's field name.
    std::string what = e.what();
    const std::string prefix = "field 'pattern': ";
    if (what.rfind(prefix, 0) == 0) what = what.substr(prefix.size());
    throw Error("", field, what);
  }
  throw Error("", field,
              "unknown pattern '" + spec + "' (valid: plain, twill:N/M, satin:N, satin:N/MOVE)");
}

}  // namespace weft
