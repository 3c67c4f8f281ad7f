#pragma once
// Cameras: perspective and orthographic, as an orthonormal basis and a film extent.
#include <string>

#include "weft/core/vec.h"
#include "weft/scenes/mesh.h"

namespace weft {

// Largest |coordinate| (metres) of a camera position. Embree traces in single precision and
// refuses ray origins beyond about 1.8e18; far below that, at 1e15 m (6.7 astronomical units) a
// float's spacing is 6.7e7 m, so nothing a camera there sees can be resolved anyway.
inline constexpr double kMaxCameraCoordinate_m = 1e15;
// Whether p is finite and within kMaxCameraCoordinate_m of the origin on every axis: a point
// Embree can trace from (a camera's position, a loaded vertex or light).
bool in_traceable_range(const Vec3& p);

struct Ray {
  Vec3 o, d;  // origin, unit direction
  double tmax = 1e300;
};

struct Camera {
  enum class Type { perspective, orthographic };
  Type type = Type::perspective;
  Vec3 position{0, 0, 0};
  // Orthonormal basis: the camera looks along 'forward'; 'up' is the film's up direction.
  Vec3 right{1, 0, 0}, up{0, 1, 0}, forward{0, 0, -1};
  double yfov_rad = 0.8;                   // perspective: vertical field of view
  double half_width = 1, half_height = 1;  // orthographic: film half extents (glTF xmag, ymag)

  // Ray through film point (fx, fy) in [0,1]^2, fx to the right, fy downwards. 'aspect' is the
  // image width / height (perspective only; an orthographic film is given by its half extents).
  Ray generate_ray(double fx, double fy, double aspect) const;

  // Error naming 'file' and 'field' unless the position is finite and within
  // kMaxCameraCoordinate_m, the basis finite and orthonormal, and the field of view (perspective)
  // or film (orthographic) finite and non-empty.
  void validate(const std::string& file, const std::string& field) const;

  // Camera with basis from a viewing direction and an up hint (Gram-Schmidt).
  static Camera look_at(Type type, const Vec3& position, const Vec3& target, const Vec3& up_hint);
};

// Orthographic camera looking along -towards_viewer whose film is exactly the projection of the
// box's 8 corners; 'up_hint' orients the film (replaced when nearly parallel to the view).
Camera frame_box_orthographic(const Bounds3& box, const Vec3& towards_viewer, const Vec3& up_hint);

}  // namespace weft
