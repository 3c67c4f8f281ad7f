// The component-wise arithmetic of Vec3 and Rgb (core/componentwise.h): each type has exactly the
// binary operators whose compound assignments it has, and they compute what the compound ones do.
#include <gtest/gtest.h>

#include "weft/core/componentwise.h"
#include "weft/core/spectrum.h"
#include "weft/core/vec.h"

using namespace weft;

namespace {

template <class A, class B>
concept Multipliable = requires(A a, B b) {
  {a * b};
};
template <class A, class B>
concept Subtractable = requires(A a, B b) {
  {a - b};
};

}  // namespace

// Rgb multiplies per channel and has no minus; Vec3 subtracts and has no product of two vectors
// (dot, cross and mul name theirs).
static_assert(Multipliable<Rgb, Rgb> && !Subtractable<Rgb, Rgb>);
static_assert(!Multipliable<Vec3, Vec3> && Subtractable<Vec3, Vec3>);
static_assert(Multipliable<Vec3, double> && Multipliable<double, Vec3> && Multipliable<Rgb, int>);
static_assert(!Multipliable<Vec3, Rgb>);

TEST(ComponentWise, OperatorsAreTheCompoundAssignments) {
  constexpr Rgb a(1, 2, 3), b(0.5, 4, -1);
  static_assert(a + b == Rgb(1.5, 6, 2));
  static_assert(a * b == Rgb(0.5, 8, -3));
  static_assert(a * 2.0 == Rgb(2, 4, 6) && 2.0 * a == a * 2.0);
  constexpr Vec3 u{1, 2, 3}, v{0.5, -1, 4};
  static_assert(u + v == Vec3{1.5, 1, 7} && u - v == Vec3{0.5, 3, -1});
  static_assert(u * 2.0 == Vec3{2, 4, 6} && 2.0 * u == u * 2.0);
  // Division multiplies by the reciprocal, as the compound form did: v / 3 is v * (1 / 3.0).
  for (double s : {3.0, 7.0, 0.1}) {
    const Vec3 q = u / s;
    EXPECT_EQ(q.x, u.x * (1.0 / s));
    EXPECT_EQ(q.z, u.z * (1.0 / s));
    EXPECT_EQ((a / s).g, a.g * (1.0 / s));
  }
}
