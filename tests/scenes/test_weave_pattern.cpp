// Interlacing matrices of the named weave patterns, checked against the definitions of the
// weaves (plain: checkerboard; twill: N over, M under, shifted one thread per pick; satin: one
// interlacing per thread, points not adjacent) rather than against stored matrices.
#include <gtest/gtest.h>

#include <numeric>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/scenes/weave_pattern.h"

using namespace weft;

namespace {
std::string pattern_error(const std::string& spec) {
  return weft::testing::error_of([&] { parse_weave_pattern(spec); });
}
}  // namespace

TEST(WeavePattern, PlainIsACheckerboard) {
  const Interlacing p = parse_weave_pattern("plain");
  ASSERT_EQ(p.warps, 2);
  ASSERT_EQ(p.wefts, 2);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      EXPECT_NE(p.over(i, j), p.over((i + 1) % 2, j));
      EXPECT_NE(p.over(i, j), p.over(i, (j + 1) % 2));
    }
  EXPECT_TRUE(p.over(0, 0));  // the convention: warp 0 over pick 0
  EXPECT_TRUE(p.floating_warps().empty());
  EXPECT_TRUE(p.floating_wefts().empty());
  // twill:1/1 is the same cloth.
  EXPECT_EQ(parse_weave_pattern("twill:1/1").warp_over, p.warp_over);
}

TEST(WeavePattern, TwillFloatsAndDiagonal) {
  for (auto [up, down] : {std::pair{2, 1}, {2, 2}, {3, 1}, {1, 3}, {5, 3}}) {
    const Interlacing t =
        parse_weave_pattern("twill:" + std::to_string(up) + "/" + std::to_string(down));
    const int r = up + down;
    ASSERT_EQ(t.warps, r);
    ASSERT_EQ(t.wefts, r);
    for (int i = 0; i < r; ++i) {
      int over = 0;
      for (int j = 0; j < r; ++j) over += t.over(i, j);
      EXPECT_EQ(over, up) << "warp " << i;  // N up, M down along every warp
      // The over-run is contiguous (cyclically): exactly one under->over change.
      int rises = 0;
      for (int j = 0; j < r; ++j) rises += !t.over(i, j) && t.over(i, (j + 1) % r);
      EXPECT_EQ(rises, 1);
    }
    // Diagonal step 1: pick j + 1 is pick j moved by one warp thread.
    for (int j = 0; j < r; ++j)
      for (int i = 0; i < r; ++i) EXPECT_EQ(t.over((i + 1) % r, (j + 1) % r), t.over(i, j));
  }
}

TEST(WeavePattern, SatinHasOneInterlacingPerThreadAndValidMove) {
  for (int n : {5, 7, 8, 9, 10, 11, 12, 16}) {
    const Interlacing s = parse_weave_pattern("satin:" + std::to_string(n));
    ASSERT_EQ(s.warps, n);
    ASSERT_EQ(s.wefts, n);
    std::vector<int> under_pick(n, -1);
    for (int i = 0; i < n; ++i) {
      int unders = 0;
      for (int j = 0; j < n; ++j)
        if (!s.over(i, j)) ++unders, under_pick[i] = j;
      EXPECT_EQ(unders, 1) << "satin " << n << " warp " << i;
    }
    for (int j = 0; j < n; ++j) {
      int unders = 0;
      for (int i = 0; i < n; ++i) unders += !s.over(i, j);
      EXPECT_EQ(unders, 1) << "satin " << n << " pick " << j;
    }
    // Interlacing points of neighbouring warps are never on neighbouring picks (that would be
    // a twill line): the move number m satisfies 1 < m < n - 1 and gcd(m, n) = 1.
    const int m = ((under_pick[1] - under_pick[0]) % n + n) % n;
    EXPECT_GT(m, 1);
    EXPECT_LT(m, n - 1);
    EXPECT_EQ(std::gcd(m, n), 1);
    for (int i = 0; i < n; ++i) EXPECT_EQ((under_pick[(i + 1) % n] - under_pick[i] + n) % n, m);
  }
  // 5-harness: move 2 or 3; explicit move numbers.
  EXPECT_EQ(parse_weave_pattern("satin:5/3").warps, 5);
  EXPECT_NE(parse_weave_pattern("satin:5/3").warp_over, parse_weave_pattern("satin:5/2").warp_over);
}

TEST(WeavePattern, ImpossibleAndMalformedPatternsAreErrors) {
  EXPECT_NE(pattern_error("satin:6").find("no 6-harness satin"), std::string::npos)
      << pattern_error("satin:6");
  EXPECT_NE(pattern_error("satin:4").find("satin"), std::string::npos);
  EXPECT_NE(pattern_error("satin:8/2").find("move number 2"), std::string::npos);  // gcd(2, 8) = 2
  EXPECT_NE(pattern_error("satin:7/1").find("not valid"), std::string::npos);
  EXPECT_NE(pattern_error("twill:0/2").find("twill"), std::string::npos);
  EXPECT_NE(pattern_error("twill:2").find("unknown pattern"), std::string::npos);
  EXPECT_NE(pattern_error("twill:a/2").find("not an integer"), std::string::npos);
  EXPECT_NE(pattern_error("twill:2/99999").find("twill"), std::string::npos);
  EXPECT_NE(pattern_error("basket").find("unknown pattern"), std::string::npos);
  EXPECT_NE(pattern_error("satin:").find("not an integer"), std::string::npos);
  EXPECT_NE(pattern_error("plain").find(""), std::string::npos);
  EXPECT_EQ(pattern_error("plain"), "");
  // The field is named.
  EXPECT_NE(pattern_error("basket").find("field 'pattern'"), std::string::npos);
}

TEST(WeavePattern, FloatingThreadsAndTransposition) {
  Interlacing m;
  m.warps = 3;
  m.wefts = 2;
  // Warp 0 always over, warp 1 alternates, warp 2 always under.
  m.warp_over = {1, 1, 0, 1, 0, 0};
  EXPECT_EQ(m.floating_warps(), (std::vector<int>{0, 2}));
  EXPECT_TRUE(m.floating_wefts().empty());
  const Interlacing t = m.transposed();
  ASSERT_EQ(t.warps, 2);
  ASSERT_EQ(t.wefts, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_EQ(t.over(j, i), !m.over(i, j));
  EXPECT_EQ(t.floating_wefts(), (std::vector<int>{0, 2}));
  EXPECT_EQ(m.drawdown(), "XX.\nX..\n");
}
