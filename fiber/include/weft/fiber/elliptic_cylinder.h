#pragma once
// An infinite cylinder of elliptical cross-section around the x axis, as a transport geometry
// (transport.h's TransportGeometry): the medium fills (y / a)^2 + (z / b)^2 <= 1, semi-axis a
// along y, b along z. With a = b it is CylinderGeometry. A flattened fiber (a collapsed cotton
// ribbon) in the experiment of fiber_layer.h.
#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/fiber/transport.h"

namespace weft {

class EllipticCylinderGeometry {
 public:
  static constexpr int kSurface = 0;

  // Semi-axes > 0 and finite, n_outside >= 1e-6 and finite.
  EllipticCylinderGeometry(double semi_axis_y, double semi_axis_z, double n_outside)
      : a_(semi_axis_y), b_(semi_axis_z), n_outside_(n_outside) {
    if (!(a_ > 0) || !std::isfinite(a_)) throw Error("", "semi_axis_y", "must be finite and > 0");
    if (!(b_ > 0) || !std::isfinite(b_)) throw Error("", "semi_axis_z", "must be finite and > 0");
    if (!(n_outside_ >= 1e-6) || !std::isfinite(n_outside_))
      throw Error("", "n_outside", "must be finite and >= 1e-6");
  }

  double semi_axis_y() const { return a_; }
  double semi_axis_z() const { return b_; }
  double n_outside(int) const { return n_outside_; }
  bool contains(const Vec3& p) const { return sqr(p.y / a_) + sqr(p.z / b_) <= 1; }

  // The cylinder's root formulas in coordinates scaled to the unit circle (the path parameter t
  // is unchanged by the scaling).
  BoundaryHit distance_to_boundary(const Vec3& p, const Vec3& d) const {
    const double py = p.y / a_, pz = p.z / b_, dy = d.y / a_, dz = d.z / b_;
    const double qa = dy * dy + dz * dz;
    if (!(qa > 0)) return {kTransportInfinity, kSurface};
    const double qb = py * dy + pz * dz;
    const double qc = py * py + pz * pz - 1;
    const double sq = std::sqrt(std::max(0.0, qb * qb - qa * qc));
    const double t = qb > 0 ? -qc / (qb + sq) : (sq - qb) / qa;
    return {std::max(0.0, t), kSurface};
  }
  Vec3 outward_normal(const Vec3& p, int) const {
    return normalize(Vec3{0, p.y / (a_ * a_), p.z / (b_ * b_)});
  }
  // Projects a point onto the wall along the ray from the axis (the axial coordinate is kept).
  Vec3 snap(Vec3 p, int) const {
    const double r = std::hypot(p.y / a_, p.z / b_);
    if (r > 0) {
      p.y /= r;
      p.z /= r;
    }
    return p;
  }
  bool valid_boundary(int boundary) const { return boundary == kSurface; }

 private:
  double a_, b_, n_outside_;
};

using EllipticCylinderTransport = PhotonTransport<EllipticCylinderGeometry>;

}  // namespace weft
