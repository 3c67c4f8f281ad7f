#pragma once
// Nonwoven samples (`weft weave --pattern nonwoven`, docs/weave.md): a random mat of straight
// fibers that tiles the plane, in the woven sample's frame and wrap convention (weave.h): the
// mat covers x, z in [-P/2, P/2] (P the tile side) and y in [-T/2, T/2] (T its thickness); a
// fiber that leaves through a side continues as the piece that enters at the same point on the
// opposite side, so a renderer can wrap rays across the sides.
//
// Model: N fibers of length L and radius r, N = the areal density's fiber length per tile
// (areal density x P^2 / (density x pi r^2)) / L, rounded. Each fiber is placed in turn: its
// centre uniform in the tile, its in-plane angle uniform (isotropic), its inclination out of the
// plane normal with the given standard deviation (redrawn beyond 80 degrees or where the fiber
// would not fit the thickness); its height is drawn uniformly from the heights where it keeps
// 2 r (1 + 2 %) from every fiber already placed (periodic copies included) and stays inside the
// slab. Where no height is free, a new centre and direction are drawn. The fibers never
// interpenetrate (measured after, as at fiber detail of a woven sample). Deterministic: the same
// options and seed give the same fibers.
#include <cstdint>

#include "weft/core/progress.h"

namespace weft {

struct WeaveOptions;
struct WovenSample;

// What the nonwoven sample was made with and what it holds (counted from its fibers).
struct NonwovenSummary {
  double areal_density_gsm = 0;  // of the fibers made
  double thickness_mm = 0;
  double solidity = 0;  // fiber volume / slab volume, of the fibers made
  double fiber_length_mm = 0, fiber_density_g_cm3 = 0, inclination_sd_deg = 0;
  int fibers = 0;    // whole fibers (each may be several curves, cut at the tile's sides)
  int attempts = 0;  // placements drawn in all (>= fibers)
  uint64_t seed = 0;
};

// The pattern name that selects the nonwoven generator.
inline constexpr const char* kNonwovenPattern = "nonwoven";

// Checks the options (weft::Error naming the field: out of range, a woven-only option given, or
// a mat whose fiber count, estimated before anything is allocated, exceeds 20 000) and builds the
// mat. Unset options take the bundled acrylic felt's values (scenes/examples/acrylic-felt.json).
// The largest mat takes tens of seconds (each fiber placed against all before it), so 'progress'
// is told before every placement drawn and between slices of the fiber-distance check, and may
// stop the work (WovenSample::cancelled: the mat is partial and must not be used).
WovenSample make_nonwoven_sample(const WeaveOptions& options,
                                 const ProgressCallback& progress = no_progress());

// The mat's size before it is made, from its options alone (the checks above, weft::Error naming
// the field): its fibers exactly, its curves (fibers cut at the tile's sides, two points each) as
// expected from the fibers' length, inclination and the tile (within a few percent of the mat
// made; placing the largest mat takes tens of seconds). And the work of placing them, expected:
// each placement tried looks at every fiber placed (nine periodic copies, most left at a glance)
// and searches the heights blocked by those that cross it seen from above; a try fails when they
// block the whole column. 'placement_tries' is the tries expected, 'crossing_checks' the crossing
// fibers searched over them and 'copy_checks' the copies glanced at (make time: ray trace books).
struct NonwovenSize {
  double fibers = 0, curves = 0;
  double placement_tries = 0, crossing_checks = 0, copy_checks = 0;
};
NonwovenSize nonwoven_sample_size(const WeaveOptions& options);

}  // namespace weft
