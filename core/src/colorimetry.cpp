#include "weft/core/colorimetry.h"

#include <cmath>
#include <cstdio>
#include <numbers>

namespace weft {

namespace {

// CIE 15:2004 eq. 8.3: the cube root above (6/29)^3, a line below it (no infinite slope at black).
constexpr double kLabEpsilon = 216.0 / 24389.0, kLabKappa = 24389.0 / 27.0;

double lab_f(double t) {
  return t > kLabEpsilon ? std::cbrt(t) : (kLabKappa * t + 16.0) / 116.0;
}
double lab_f_inverse(double f) {
  const double t = f * f * f;
  return t > kLabEpsilon ? t : (116.0 * f - 16.0) / kLabKappa;
}

double degrees(double radians) {
  return radians * 180.0 / std::numbers::pi;
}
double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

// The hue angle of (a', b') in degrees, [0, 360); 0 for a neutral (Sharma et al. eq. 4).
double hue_degrees(double a, double b) {
  if (a == 0 && b == 0) return 0;
  const double h = degrees(std::atan2(b, a));
  return h < 0 ? h + 360.0 : h;
}

}  // namespace

Xyz d65_white(Observer observer) {
  Spectrum ones;
  ones.fill(1.0);
  return reflectance_to_xyz_d65(ones, observer);
}

Lab xyz_to_lab(const Xyz& c, const Xyz& w) {
  const double fx = lab_f(c.x / w.x), fy = lab_f(c.y / w.y), fz = lab_f(c.z / w.z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Xyz lab_to_xyz(const Lab& lab, const Xyz& w) {
  const double fy = (lab.l + 16.0) / 116.0;
  const double fx = fy + lab.a / 500.0, fz = fy - lab.b / 200.0;
  return {w.x * lab_f_inverse(fx), w.y * lab_f_inverse(fy), w.z * lab_f_inverse(fz)};
}

Lab reflectance_to_lab(const Spectrum& reflectance, Observer observer) {
  return xyz_to_lab(reflectance_to_xyz_d65(reflectance, observer), d65_white(observer));
}

double srgb_gamma_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

Xyz linear_srgb_to_xyz(const Rgb& c) {
  // IEC 61966-2-1's RGB -> XYZ matrix (the inverse of xyz_to_linear_srgb's to 4 digits).
  return {0.4124 * c.r + 0.3576 * c.g + 0.1805 * c.b, 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b,
          0.0193 * c.r + 0.1192 * c.g + 0.9505 * c.b};
}

Lab linear_srgb_to_lab(const Rgb& linear) {
  return xyz_to_lab(linear_srgb_to_xyz(linear), linear_srgb_to_xyz(Rgb(1.0)));
}

double delta_e00(const Lab& x, const Lab& y) {
  // Sharma, Wu and Dalal (2005), eqs. 2-22.
  const double c_mean = 0.5 * (std::hypot(x.a, x.b) + std::hypot(y.a, y.b));
  const double c7 = std::pow(c_mean, 7);
  const double g = 0.5 * (1 - std::sqrt(c7 / (c7 + std::pow(25.0, 7))));
  const double a1 = (1 + g) * x.a, a2 = (1 + g) * y.a;
  const double c1 = std::hypot(a1, x.b), c2 = std::hypot(a2, y.b);
  const double h1 = hue_degrees(a1, x.b), h2 = hue_degrees(a2, y.b);
  const bool neutral = c1 * c2 == 0;
  double dh = neutral ? 0 : h2 - h1;
  if (dh > 180) dh -= 360;
  if (dh < -180) dh += 360;
  const double d_l = y.l - x.l, d_c = c2 - c1;
  const double d_h = 2 * std::sqrt(c1 * c2) * std::sin(radians(dh / 2));
  const double l_mean = 0.5 * (x.l + y.l), cp_mean = 0.5 * (c1 + c2);
  double h_mean = h1 + h2;
  if (!neutral) {
    if (std::abs(h1 - h2) > 180) h_mean += h_mean < 360 ? 360 : -360;
    h_mean /= 2;
  }
  const double t = 1 - 0.17 * std::cos(radians(h_mean - 30)) +
                   0.24 * std::cos(radians(2 * h_mean)) + 0.32 * std::cos(radians(3 * h_mean + 6)) -
                   0.20 * std::cos(radians(4 * h_mean - 63));
  const double d_theta = 30 * std::exp(-std::pow((h_mean - 275) / 25, 2));
  const double cp7 = std::pow(cp_mean, 7);
  const double r_c = 2 * std::sqrt(cp7 / (cp7 + std::pow(25.0, 7)));
  const double l50 = (l_mean - 50) * (l_mean - 50);
  const double s_l = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double s_c = 1 + 0.045 * cp_mean, s_h = 1 + 0.015 * cp_mean * t;
  const double r_t = -std::sin(radians(2 * d_theta)) * r_c;
  const double tl = d_l / s_l, tc = d_c / s_c, th = d_h / s_h;
  return std::sqrt(tl * tl + tc * tc + th * th + r_t * tc * th);
}

std::string format_lab(const Lab& lab) {
  char buf[80];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f)", lab.l, lab.a, lab.b);
  return buf;
}

}  // namespace weft
