#include "weft/scenes/camera.h"

#include <cmath>

#include "message_format.h"
#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {

Ray Camera::generate_ray(double fx, double fy, double aspect) const {
  const double sx = 2 * fx - 1, sy = 1 - 2 * fy;  // film coordinates in [-1, 1], y up
  if (type == Type::orthographic)
    return {position + right * (sx * half_width) + up * (sy * half_height), forward};
  const double th = std::tan(0.5 * yfov_rad);
  return {position, normalize(forward + right * (sx * th * aspect) + up * (sy * th))};
}

namespace {

bool within(const Vec3& v, double bound) {
  return is_finite(v) && std::abs(v.x) <= bound && std::abs(v.y) <= bound && std::abs(v.z) <= bound;
}

std::string format_vec(const Vec3& v) {
  return detail::format_triple(v.x, v.y, v.z);
}
using detail::format_number;

}  // namespace

bool in_traceable_range(const Vec3& p) {
  return within(p, kMaxCameraCoordinate_m);
}

void Camera::validate(const std::string& file, const std::string& field) const {
  if (!in_traceable_range(position))
    throw Error(file, field,
                "camera position " + format_vec(position) + " is not finite or beyond " +
                    format_number(kMaxCameraCoordinate_m) + " m");
  const double tol = 1e-6;
  for (const Vec3* v : {&right, &up, &forward})
    if (!is_finite(*v) || std::abs(length(*v) - 1) > tol)
      throw Error(file, field, "camera basis is not finite and unit length");
  if (std::abs(dot(right, up)) > tol || std::abs(dot(right, forward)) > tol ||
      std::abs(dot(up, forward)) > tol)
    throw Error(file, field, "camera basis is not orthogonal");
  if (type == Type::perspective && !(yfov_rad > 0 && yfov_rad < kPi))
    throw Error(file, field, "perspective field of view must lie in (0, pi)");
  if (type == Type::orthographic &&
      !(half_width > 0 && half_height > 0 && half_width <= 1e30 && half_height <= 1e30))
    throw Error(file, field, "orthographic film extents must be finite and positive");
}

Camera Camera::look_at(Type type, const Vec3& position, const Vec3& target, const Vec3& up_hint) {
  if (!in_traceable_range(position))
    throw Error("camera position " + format_vec(position) + " is not finite or beyond " +
                format_number(kMaxCameraCoordinate_m) + " m");
  if (!within(target, 1e300) || !within(up_hint, 1e300))
    throw Error("look_at and up must be finite");
  Camera c;
  c.type = type;
  c.position = position;
  const Vec3 f = target - position;
  if (!(length(f) > 0)) throw Error("look_at equals position");
  c.forward = normalize(f);
  Vec3 r = cross(c.forward, up_hint);
  if (!(length(r) > 1e-12 * length(up_hint))) throw Error("up is parallel to the view");
  c.right = normalize(r);
  c.up = cross(c.right, c.forward);
  return c;
}

Camera frame_box_orthographic(const Bounds3& box, const Vec3& towards_viewer, const Vec3& up_hint) {
  Camera c;
  c.type = Camera::Type::orthographic;
  c.forward = -normalize(towards_viewer);
  Vec3 hint = up_hint;
  // Replace a hint (nearly) parallel to the view by any perpendicular direction.
  if (std::abs(dot(normalize(hint), c.forward)) > 0.999)
    hint = std::abs(c.forward.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  c.right = normalize(cross(c.forward, hint));
  c.up = cross(c.right, c.forward);
  double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300, zlo = 1e300;
  const Vec3 centre = box.center();
  for (int i = 0; i < 8; ++i) {
    const Vec3 d = box.corner(i) - centre;
    xlo = std::min(xlo, dot(d, c.right)), xhi = std::max(xhi, dot(d, c.right));
    ylo = std::min(ylo, dot(d, c.up)), yhi = std::max(yhi, dot(d, c.up));
    zlo = std::min(zlo, dot(d, c.forward));
  }
  c.half_width = 0.5 * (xhi - xlo);
  c.half_height = 0.5 * (yhi - ylo);
  // A flat box seen edge-on would give an empty film; keep it finite and non-zero.
  const double extent = length(box.hi - box.lo);
  const double min_half = 1e-9 * std::max(extent, 1e-30);
  c.half_width = std::max(c.half_width, min_half);
  c.half_height = std::max(c.half_height, min_half);
  // Film centre on the projected box centre, in front of the nearest corner.
  c.position = centre + c.right * (0.5 * (xlo + xhi)) + c.up * (0.5 * (ylo + yhi)) +
               c.forward * (zlo - 0.01 * extent - 1e-9);
  return c;
}

}  // namespace weft
