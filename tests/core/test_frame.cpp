// Frames: orthonormal and right-handed, to_local and to_world inverse to each other, and the fiber
// convention of frame.h (local x = tangent = fiber axis, y = binormal = n x t, z = normal).
#include <gtest/gtest.h>

#include <cmath>

#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"

using namespace weft;

namespace {

Vec3 random_unit(Rng& rng) {
  const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
  const double s = safe_sqrt(1 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Unit axes, mutually orthogonal, s x t = n; 1e-12 allows a few roundings of unit-size products.
void expect_orthonormal_right_handed(const Frame& f) {
  for (const Vec3& a : {f.s, f.t, f.n}) EXPECT_NEAR(length(a), 1.0, 1e-12);
  EXPECT_NEAR(dot(f.s, f.t), 0.0, 1e-12);
  EXPECT_NEAR(dot(f.t, f.n), 0.0, 1e-12);
  EXPECT_NEAR(dot(f.n, f.s), 0.0, 1e-12);
  EXPECT_NEAR(length(cross(f.s, f.t) - f.n), 0.0, 1e-12);
}

}  // namespace

TEST(Frame, FromNormalIsOrthonormalAndRoundTrips) {
  Rng rng(3);
  // Random normals, the poles, and the neighbourhood of n.z = -1 where the construction switches
  // branch.
  std::vector<Vec3> normals = {{0, 0, 1},
                               {0, 0, -1},
                               {1, 0, 0},
                               {0, -1, 0},
                               normalize(Vec3{1e-9, 0, -1}),
                               normalize(Vec3{0, 1e-9, -1})};
  for (int i = 0; i < 200; ++i) normals.push_back(random_unit(rng));
  for (const Vec3& n : normals) {
    SCOPED_TRACE(::testing::Message() << "n " << n);
    const Frame f = Frame::from_normal(n);
    expect_orthonormal_right_handed(f);
    EXPECT_EQ(f.n, n);
    const Vec3 v = random_unit(rng) * 3.5;
    EXPECT_NEAR(length(f.to_world(f.to_local(v)) - v), 0.0, 1e-12);
    EXPECT_NEAR(length(f.to_local(f.to_world(v)) - v), 0.0, 1e-12);
    EXPECT_NEAR(length(f.to_local(n) - Vec3{0, 0, 1}), 0.0, 1e-12);
    EXPECT_NEAR(cos_theta(f.to_local(v)), dot(v, n), 1e-12);
  }
}

TEST(Frame, FromNormalTangentKeepsTheTangentDirection) {
  Rng rng(5);
  for (int i = 0; i < 200; ++i) {
    const Vec3 n = random_unit(rng);
    const Vec3 hint = random_unit(rng) * 2.0;  // any length, not perpendicular to n
    const Frame f = Frame::from_normal_tangent(n, hint);
    expect_orthonormal_right_handed(f);
    EXPECT_EQ(f.n, n);
    // s is the hint with its normal component removed: same direction, not reversed.
    const Vec3 projected = hint - dot(hint, n) * n;
    EXPECT_NEAR(length(f.s - normalize(projected)), 0.0, 1e-12);
    // The fiber convention: x = tangent t, y = binormal b = n x t, z = normal n.
    EXPECT_NEAR(length(f.t - cross(n, f.s)), 0.0, 1e-12);
    const Vec3 local_hint = f.to_local(hint);
    EXPECT_GT(local_hint.x, 0.0);
    EXPECT_NEAR(local_hint.y, 0.0, 1e-12);
  }
}

TEST(Frame, FiberFrameOfACylinderAlongX) {
  // A fiber along x with the surface point at angle phi around it: outward normal
  // n = (0, cos phi, sin phi), tangent t = (1, 0, 0), b = n x t = (0, sin phi, -cos phi).
  for (double phi : {0.0, 0.7, kPi / 2, 2.5, -1.2}) {
    const Vec3 n{0, std::cos(phi), std::sin(phi)}, t{1, 0, 0};
    const Frame f = Frame::from_normal_tangent(n, t);
    EXPECT_NEAR(length(f.s - t), 0.0, 1e-15);
    EXPECT_NEAR(length(f.t - Vec3{0, std::sin(phi), -std::cos(phi)}), 0.0, 1e-15);
    EXPECT_NEAR(length(f.to_local(t) - Vec3{1, 0, 0}), 0.0, 1e-15);
    EXPECT_NEAR(length(f.to_local(n) - Vec3{0, 0, 1}), 0.0, 1e-15);
  }
}

TEST(Frame, TangentAlongTheNormalFallsBackToAnyFrame) {
  const Vec3 n = normalize(Vec3{0.3, -0.4, 0.5});
  for (const Vec3& hint : {n, -2.0 * n, Vec3{0, 0, 0}}) {
    const Frame f = Frame::from_normal_tangent(n, hint);
    expect_orthonormal_right_handed(f);
    EXPECT_EQ(f.n, n);
  }
}

TEST(Frame, SphericalDirectionHasTheGivenAngles) {
  for (double theta : {0.0, 0.3, kPi / 2, 2.0, kPi})
    for (double phi : {0.0, 1.0, 4.0}) {
      const Vec3 w = spherical_direction(theta, phi);
      EXPECT_NEAR(length(w), 1.0, 1e-15);
      EXPECT_NEAR(cos_theta(w), std::cos(theta), 1e-15);
      if (std::sin(theta) > 1e-6) {
        EXPECT_NEAR(std::atan2(w.y, w.x), std::remainder(phi, 2 * kPi), 1e-12);
      }
    }
}
