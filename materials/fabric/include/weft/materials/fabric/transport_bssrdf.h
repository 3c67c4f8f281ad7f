#pragma once
// The fiber BSSRDF of the paper (Voloboy, Galaktionov & Lobalzo 2010, section 3.1): photons enter
// the cylinder at one surface point A from a given direction, and their exits are binned on a
// (u, v) grid over the whole cylinder surface and an angular grid per cell:
//   BSSRDF(w_in, A, w_out, B_i) = F_out / (d omega_out * B_i * cos theta_out * F_in).
//
// Conventions:
// * Because the cylinder is invariant under shifts along and turns around its axis (the paper's
//   Fig. 4), the table is a function of the offset of B from A only: u is the angle around the
//   axis from A (cell k is centred on u = 2 pi k / u_bins, so cell 0 holds A), v the axial offset
//   from A (v_bins cells over [-v_range, v_range]; exits outside go to 'overflow').
//   Entering at a single point is the limit of a small area A.
// * Directions are in the local fiber frame of the point they belong to (DESIGN.md: t = fiber
//   axis = local x, b = n x t = local y, n = outward normal = local z), pointing away from the
//   surface. w_in points towards the light: photons travel along -w_in.
// * Angular cells: cos theta_out in [0, 1] in theta_bins equal steps (equal solid angle), times
//   phi_out = atan2(w.y, w.x) in [0, 2 pi) in phi_bins steps. The cos theta_out of the formula is
//   the cell's average, so the divisor is the cell's projected solid angle
//   int cos dw = (2 pi / phi_bins) (c1^2 - c0^2) / 2: exact for a radiance constant over the cell.
// * F_in is the power arriving at A (before the Fresnel reflection at entry, which belongs to the
//   surface term of the fiber BRDF); values are in 1 / (sr * length^2) in the medium's length unit.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "weft/materials/fabric/transport.h"
#include "weft/materials/fabric/transport_batch.h"

namespace weft {

struct BssrdfGridSpec {
  int u_bins = 64;     // around the circumference
  int v_bins = 65;     // along the axis (odd: a cell centred on A)
  double v_range = 0;  // half-length of the axial window [length], > 0
  int theta_bins = 8;  // outgoing cos theta
  int phi_bins = 16;   // outgoing azimuth

  void validate() const;  // weft::Error naming the field
  size_t cells() const { return static_cast<size_t>(u_bins) * v_bins * theta_bins * phi_bins; }
  size_t index(int iu, int iv, int it, int ip) const {
    return ((static_cast<size_t>(iu) * v_bins + iv) * theta_bins + it) * phi_bins + ip;
  }
};

// Maps an exit to its cell relative to the entry point A = (x 0, angle 0) of CylinderGeometry
// (the point (0, r, 0)).
class BssrdfBinner {
 public:
  BssrdfBinner(const BssrdfGridSpec& grid, double radius);

  const BssrdfGridSpec& grid() const { return grid_; }
  // grid.index() of the cell, or -1 when the exit lies outside the axial window.
  int64_t cell(const ExitEvent& e) const;

 private:
  BssrdfGridSpec grid_;
  double radius_;
  double u_scale_, v_scale_, phi_scale_;
};

// Dense table of exit weights per cell: an ExitRecorder for single-threaded use and the merged
// result of simulate_bssrdf.
class BssrdfRecorder {
 public:
  BssrdfRecorder(const BssrdfGridSpec& grid, double radius);

  void on_exit(const ExitEvent& e) {
    const int64_t k = binner_.cell(e);
    if (k < 0)
      overflow_ += e.weight;
    else
      add(static_cast<size_t>(k), e.weight);
  }
  void add(size_t cell, double weight) {
    sum_[cell] += weight;
    sum2_[cell] += weight * weight;
  }
  void add_overflow(double weight) { overflow_ += weight; }

  const BssrdfGridSpec& grid() const { return binner_.grid(); }
  const BssrdfBinner& binner() const { return binner_; }
  // Sum of exit weights per cell and of their squares (a photon exits once, so per-photon
  // contributions are single weights).
  const std::vector<double>& weight_sum() const { return sum_; }
  const std::vector<double>& weight_sum2() const { return sum2_; }
  double overflow() const { return overflow_; }  // weight that left outside the axial window
  double binned() const;                         // weight that landed in cells

 private:
  BssrdfBinner binner_;
  std::vector<double> sum_, sum2_;
  double overflow_ = 0;
};

struct BssrdfSetup {
  TransportMedium medium;
  double radius = 1;
  double n_outside = 1;
  Vec3 incident{0, 0, 1};  // w_in in A's local frame (towards the light), unit, z > 0
  BssrdfGridSpec grid;
  TransportOptions options;

  void validate() const;
};

struct BssrdfTable {
  BssrdfGridSpec grid;
  double radius = 0;
  Vec3 incident;
  std::vector<double> value;      // BSSRDF per cell [1 / (sr length^2)], grid.index() order
  std::vector<double> std_error;  // its standard error
  // Fractions of F_in.
  MeanEstimate specular, exited, absorbed, roulette, lost;
  double overflow = 0;  // exited outside the axial window (part of 'exited')
  uint64_t photons = 0;
  uint64_t scatterings = 0;
  bool cancelled = false;

  double cell_area() const;                           // B_i = r du dv
  double projected_solid_angle(int theta_bin) const;  // int cos dw over one angular cell
  // Cell centres: u offset [rad], v offset [length], outgoing direction in B's local frame.
  double u_center(int iu) const;
  double v_center(int iv) const;
  Vec3 direction_center(int it, int ip) const;
};

// Traces batch.photons photons into A. Tasks keep compact lists of (cell, weight) exits, which are
// added to the table in task order, so the table has the same bits at any thread count.
BssrdfTable simulate_bssrdf(const BssrdfSetup& setup, const PhotonBatchOptions& batch);

}  // namespace weft
