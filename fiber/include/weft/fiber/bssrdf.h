#pragma once
// The fiber BSSRDF of the paper (Voloboy, Galaktionov & Lobalzo 2010, section 3.1), the one
// implementation: photons enter the cylinder at one surface point A (through enter_fiber, so the
// boundary is the band's own), and their exits are binned by the offset of the exit point B from
// A and by the exit direction in B's frame:
//   BSSRDF(w_in, A, w_out, B_i) = F_out / (D_out * B_i * F_in),
// with D_out = int over the exit direction bin of cos theta_out d omega (the paper's
// d omega_out cos theta_out, exact for a radiance constant over the bin) and B_i the area of the
// exit cell. The fiber baker's BSSRDF route sums it over the lit cells (fiber_bake.h); tests and
// benchmarks use it directly.
//
// Conventions:
// * The fiber's axis is the world x axis; A is the top of the fiber, angle pi/2 (its local frame
//   is the world frame). The cylinder is invariant under shifts along and turns around its axis
//   (the paper's Fig. 4), so only the offset of B from A matters: u is the angle around the axis
//   from A (cell k centred on u = 2 pi k / u_bins, so cell 0 holds A; u_bins even), v the axial
//   offset (v_bins cells over [-v_range, v_range]; exits beyond go to 'overflow'; an infinite
//   v_range with v_bins = 1 sums over the whole axis, as the BRDF needs).
// * Directions are in the local frame of their point (x = axis t, y = b = n x t, z = outward n),
//   pointing away from the surface; w_in points towards the light.
// * Exit directions are binned on the tables' DirectionGrid (core/direction_grid.h) at
//   direction_resolution, the one direction <-> bin mapping of the project.
// * F_in is the power arriving at A, before the surface reflects part of it.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/transport_batch.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct BssrdfGrid {
  int u_bins = 180;  // around the axis, even
  int v_bins = 1;    // along the axis
  double v_range = kTransportInfinity;
  int direction_resolution = 8;  // R: exit directions on R x R octahedral bins
  // Whether the surface lobe's reflection at A is binned (the BRDF needs it: it is the surface
  // part of the fiber BSDF) or only booked (the subsurface BSSRDF of the paper).
  bool surface_in_table = true;
  // Keep per-cell sums of squared weights (standard errors); costs a second table.
  bool keep_squares = false;

  void validate() const;  // weft::Error naming the field
  DirectionGrid directions() const { return {direction_resolution}; }
  size_t cells() const {
    return static_cast<size_t>(u_bins) * v_bins * static_cast<size_t>(directions().bins());
  }
  size_t index(int iu, int iv, int direction_bin) const {
    return (static_cast<size_t>(iu) * v_bins + iv) * directions().bins() + direction_bin;
  }
  // Angle of u cell iu from A in (-pi, pi]; centre of v cell iv.
  double u_center(int iu) const;
  double v_center(int iv) const;
  // index() of the cell an exit falls in (A at the top of the fiber, axial position 0), or -1
  // beyond the axial window. validate() first.
  int64_t cell_of(const ExitEvent& e) const;
};

// The light arriving at A, in A's local frame. Either one direction (every photon, weight 1), or
// bins over A's lit hemisphere in s (axial cosine, s_bins steps over [-1, 1]) and psi (azimuth
// about the axis from n towards b, psi_bins steps over [-pi/2, pi/2]): photon k visits bin
// k mod bins, uniformly in solid angle within it, with flux weight cos theta_A.
struct BssrdfIncidence {
  std::optional<Vec3> direction;
  int s_bins = 1, psi_bins = 1;

  static BssrdfIncidence from(const Vec3& w_in);
  static BssrdfIncidence binned(int s_bins, int psi_bins);
  int bins() const { return direction ? 1 : s_bins * psi_bins; }
  void validate() const;  // weft::Error naming the field
};

struct BssrdfResult {
  BssrdfGrid grid;
  BssrdfIncidence incidence;
  double radius = 0;
  // Per incident bin b and exit cell c (index b * grid.cells() + c): sums of exit weights (and of
  // their squares with keep_squares), the power that arrived (F_in) and the photons per bin.
  std::vector<double> exit_weight, exit_weight2;
  std::vector<double> flux_in;
  std::vector<uint64_t> photons_in;
  double overflow = 0;  // exit weight beyond the axial window
  PhotonTally books;    // energy books of every photon (fractions: divide by books.launched)
  bool cancelled = false;

  // F_out / F_in of a cell: the fraction of the power arriving in bin b that left through it.
  double transfer(int bin, size_t cell) const;
  double cell_area() const;  // B_i = r du dv (finite v_range only)
  // BSSRDF of a cell [1 / (sr length^2)] and its standard error (keep_squares).
  MeanEstimate value(int bin, int iu, int iv, int direction_bin) const;

 private:
  friend BssrdfResult simulate_bssrdf(const FiberBandPhysics&, const BssrdfGrid&,
                                      const BssrdfIncidence&, const TaskBatch&);
  std::vector<double> direction_areas_;  // D_out per direction bin
};

// Traces batch.items photons into A. Tasks keep compact lists of (cell, weight) exits, merged in
// task order, so the result has the same bits at any thread count.
BssrdfResult simulate_bssrdf(const FiberBandPhysics& fiber, const BssrdfGrid& grid,
                             const BssrdfIncidence& incidence, const TaskBatch& batch);

}  // namespace weft
