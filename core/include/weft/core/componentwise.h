#pragma once
// The binary arithmetic of the small component-wise value types (Vec3, Rgb), written once from
// each type's compound assignments: a type opts in by setting kComponentWise<T> and gets each of
// these operators whose compound form it has (a + b from +=, v * s from *= double, ...).
namespace weft {

template <class T>
inline constexpr bool kComponentWise = false;

template <class T>
concept ComponentWise = kComponentWise<T>;

template <ComponentWise T>
requires requires(T& a, const T& b) {
  a += b;
}
constexpr T operator+(T a, const T& b) {
  return a += b;
}
template <ComponentWise T>
requires requires(T& a, const T& b) {
  a -= b;
}
constexpr T operator-(T a, const T& b) {
  return a -= b;
}
template <ComponentWise T>
requires requires(T& a, const T& b) {
  a *= b;
}
constexpr T operator*(T a, const T& b) {
  return a *= b;
}
template <ComponentWise T>
constexpr T operator*(T a, double s) {
  return a *= s;
}
template <ComponentWise T>
constexpr T operator*(double s, T a) {
  return a *= s;
}
template <ComponentWise T>
constexpr T operator/(T a, double s) {
  return a *= (1.0 / s);
}

}  // namespace weft
