// Bad input in the scene library: sizes counted before anything is allocated.
#include <gtest/gtest.h>

#include <string>

#include "test_util.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/wif.h"

using namespace weft;
using weft::testing::error_of;

// 3e7 curve points (the weave's own limit) as tubes of 32 sides made 2e9 triangles and died of
// std::bad_alloc; the count is refused first, naming the setting.
TEST(BadInput, FiberTubesWithTooManyTrianglesAreRefusedBeforeAllocating) {
  FiberCurves c;
  const uint32_t points = 1000000;  // 999999 segments: 2 x 32 x 999999 = 6.4e7 triangles
  c.points.assign(4 * size_t{points}, 0.0f);
  for (uint32_t i = 0; i < points; ++i)
    c.points[4 * i] = float(i) * 1e-6f, c.points[4 * i + 3] = 1e-7f;
  c.curve_first = {0};
  c.curve_points = {points};
  c.curve_yarn = {0};
  c.yarn_material = {"warp"};
  const std::string msg = error_of([&] { make_fiber_tubes(c, 32); });
  EXPECT_NE(msg.find("fiber_geometry.sides"), std::string::npos) << msg;
  EXPECT_NE(msg.find("999999 fiber segments make 6.39999e+07 triangles (limit 5e7)"),
            std::string::npos)
      << msg;
  // Fewer sides fit: 3 sides make 6e6 triangles.
  EXPECT_EQ(make_fiber_tubes(c, 3).mesh.triangle_count(), 2 * 3 * size_t{points - 1});
}

// The interlacing and the treadling are computed on shaft bit masks (a hostile draft threading
// every warp on all 4096 shafts cost one operation per listed shaft per crossing); shafts past
// the first 64-bit word must land on the right warps. Expected values from the WIF rules in
// wif.h: rising shed, warp i is over pick j when one of its shafts is lifted on j.
TEST(BadInput, WifShaftsBeyondSixtyFourInterlaceCorrectly) {
  const std::string head = R"([WEAVING]
Shafts=130
Treadles=2
[WARP]
Threads=3
[WEFT]
Threads=2
[THREADING]
1=65
2=130
3=1
)";
  const WifDraft lift = parse_wif(head + "[LIFTPLAN]\n1=65\n2=130,1\n", "lift.wif");
  const WifDraft tread =
      parse_wif(head + "[TIEUP]\n1=65\n2=1,130\n[TREADLING]\n1=1\n2=2\n", "tread.wif");
  EXPECT_EQ(tread.weft[1].shafts, (std::vector<int>{1, 130}));
  for (const WifDraft* d : {&lift, &tread}) {
    const Interlacing m = d->interlacing();
    ASSERT_EQ(m.warps, 3);
    ASSERT_EQ(m.wefts, 2);
    // Row j (pick), column i (warp).
    EXPECT_EQ(m.warp_over, (std::vector<uint8_t>{1, 0, 0, 0, 1, 1})) << d->source;
  }
}
