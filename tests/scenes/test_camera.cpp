// Cameras: ray generation and the orthographic framing of a box.
#include <gtest/gtest.h>

#include <cmath>

#include "weft/scenes/camera.h"

using namespace weft;

TEST(Camera, PerspectiveCentreAndCorners) {
  const Camera c = Camera::look_at(Camera::Type::perspective, {0, 0, 0}, {0, 0, -1}, {0, 1, 0});
  const Ray centre = c.generate_ray(0.5, 0.5, 2.0);
  EXPECT_NEAR(centre.d.z, -1, 1e-12);
  // Top edge centre: the vertical half angle is yfov / 2.
  const Ray top = c.generate_ray(0.5, 0.0, 2.0);
  EXPECT_NEAR(std::atan2(top.d.y, -top.d.z), 0.5 * c.yfov_rad, 1e-12);
  // Right edge: horizontal tangent is aspect x vertical tangent.
  const Ray right = c.generate_ray(1.0, 0.5, 2.0);
  EXPECT_NEAR(right.d.x / -right.d.z, 2 * std::tan(0.5 * c.yfov_rad), 1e-12);
}

TEST(Camera, OrthographicFramingTouchesTheProjectedBox) {
  Bounds3 box;
  box.expand(Vec3{-1, -0.5, -2});
  box.expand(Vec3{3, 0.5, 2});
  const Vec3 view = normalize(Vec3{0.3, 1, 0.2});
  const Camera c = frame_box_orthographic(box, view, {0, 1, 0});
  EXPECT_NEAR(dot(c.forward, -view), 1, 1e-12);
  // Every corner projects inside the film and the extremes touch its edges.
  double max_x = 0, max_y = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3 d = box.corner(i) - c.position;
    EXPECT_GT(dot(d, c.forward), 0);  // in front of the film
    const double x = dot(d, c.right) / c.half_width, y = dot(d, c.up) / c.half_height;
    EXPECT_LE(std::abs(x), 1 + 1e-9);
    EXPECT_LE(std::abs(y), 1 + 1e-9);
    max_x = std::max(max_x, std::abs(x));
    max_y = std::max(max_y, std::abs(y));
  }
  EXPECT_NEAR(max_x, 1, 1e-9);
  EXPECT_NEAR(max_y, 1, 1e-9);
  // Film corners map to rays along forward.
  const Ray r = c.generate_ray(0, 0, 1);
  EXPECT_NEAR(dot(r.d, c.forward), 1, 1e-12);
  EXPECT_NEAR(dot(r.o - c.position, c.right), -c.half_width, 1e-9);
  EXPECT_NEAR(dot(r.o - c.position, c.up), c.half_height, 1e-9);
}
