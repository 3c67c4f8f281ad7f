// Issue 10, "Bad input", in the scene library: sizes counted before anything is allocated.
#include <gtest/gtest.h>

#include <string>

#include "test_util.h"
#include "weft/scenes/curves.h"

using namespace weft;
using weft::testing::error_of;

// 3e7 curve points (the weave's own limit) as tubes of 32 sides made 2e9 triangles and died of
// std::bad_alloc; the count is refused first, naming the setting.
TEST(BadInput, FiberTubesWithTooManyTrianglesAreRefusedBeforeAllocating) {
  FiberCurves c;
  const uint32_t points = 1'000'000;  // 999999 segments: 6.4e7 triangles at 32 sides
  c.points.assign(4 * size_t{points}, 0.0f);
  for (uint32_t i = 0; i < points; ++i)
    c.points[4 * i] = float(i) * 1e-6f, c.points[4 * i + 3] = 1e-7f;
  c.curve_first = {0};
  c.curve_points = {points};
  c.curve_yarn = {0};
  c.yarn_material = {"warp"};
  const std::string msg = error_of([&] { make_fiber_tubes(c, 32); });
  EXPECT_NE(msg.find("fiber_geometry.sides"), std::string::npos) << msg;
  EXPECT_NE(msg.find("6.4e+07 triangles (limit 5e7)"), std::string::npos) << msg;
  // Fewer sides fit: 3 sides make 6e6 triangles.
  EXPECT_EQ(make_fiber_tubes(c, 3).mesh.triangle_count(), 2 * 3 * size_t{points - 1});
}
