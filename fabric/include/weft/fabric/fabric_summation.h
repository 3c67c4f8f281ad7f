#pragma once
// Fabric BSDF tables from a fiber table by summation, the fast approximations beside the ray-traced
// reference (fabric/fabric_raytrace.h). Both tabulate a cloth's BSDF in the cloth frame
// (x = warp, z = the cloth's normal, y = z x x), on the tables' grid, as cosine-weighted cell
// averages (materials/bsdf_table.h).
//
// * kPaper: the paper's formula (Voloboy, Galaktionov & Lobalzo 2010, section 3.2):
//     f_fabric(w_i, w_o) = 1/2 sum over {warp, weft} of f_fiber(w_i, w_o in that fiber's frame),
//   a fiber along the warp (t = x) or the weft (t = y), looked at on its top (n = the cloth's
//   normal). One point per orientation; a view below the cloth is below that point's horizon, so
//   nothing leaves below the cloth: light from above is never transmitted, and the underside is
//   black. Light from below still reaches a view from above, through the fiber table's light
//   from behind the point: the table is not reciprocal (TabulatedBsdfTable::
//   directional_albedo_seen_from).
// * kVisible: our extension. Each orientation of the fibers seen at the cloth's surface (from the
//   woven sample's own geometry, with weights) stands for a closed layer of parallel fibers of
//   radius R at pitch 2R; the cloth's radiance towards w_o is the fibers' radiance averaged over
//   the part of their circumference that w_o sees past the neighbouring fibers (masking), and each
//   fiber is lit over the part of its width its neighbours leave to w_i (shadowing: a fraction
//   |cos alpha_i| of an isolated fiber, alpha_i the light's angle from the normal across the
//   fiber). Per unit cloth area the layer holds 1 / (2R) of fiber length, so
//     f = s_i / (2 |cos theta_i| |cos theta_o|) * int_{B seen} f_fiber(w_i, w_o at B)
//         |cos theta_i(B)| |cos theta_o(B)| d phi_B,
//   which reduces to the layer's single scattering: it adds the fibers' flanks (views away from
//   the normal see the sides of the fibers, whose frames differ), the orientations the weave
//   really has (crimp and twist tilt fibers out of the cloth's plane), masking and shadowing
//   between neighbours, and transmission (views from below see the layer's underside), but still
//   no light that travels between fibers (the ray-traced reference has it).
#include <cstdint>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/vec.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

enum class FabricSummation { kPaper, kVisible };

// A fiber direction at the cloth's surface (unit, cloth frame) and its share of the visible area.
struct FiberOrientation {
  Vec3 tangent;
  double weight = 1;
};

struct FabricSummationOptions {
  FabricSummation method = FabricSummation::kPaper;
  int resolution = 8;        // of the fabric table (DirectionGrid R)
  int samples_per_cell = 8;  // stratified direction pairs per cell pair (from_function)
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  // kVisible: orientations seen from above (views with w_o.z > 0) and from below; empty means the
  // paper's two, warp (1, 0, 0) and weft (0, 1, 0), with equal weights.
  std::vector<FiberOrientation> top, bottom;
  int circumference_samples = 64;  // kVisible: points B around each fiber (midpoint rule)

  void validate() const;  // weft::Error naming the field
};

// Lower bounds on the CPU time of one direction pair of a summation table (R = DirectionGrid
// resolution: (2 R^2)^2 cell pairs x samples_per_cell pairs), seconds, for a front end's estimate
// before it starts. PERFORMANCE.md's fabric tables (R = 8, 8 samples: 131 072 pairs, 2 threads):
// the paper's summation 0.035 s, 0.53 us per pair per core; summation-visible 1.72 s, 26 us (its
// cost grows with the visible orientations, so a sample with fewer is cheaper): 0.1 and 5 us.
inline constexpr double kMinSecondsPerPaperPair = 0.1e-6;
inline constexpr double kMinSecondsPerVisiblePair = 5e-6;

// The fabric table (kind "fabric", the fiber table's channels) from a fiber table.
TabulatedBsdfTable sum_fabric_table(const TabulatedBsdfTable& fiber,
                                    const FabricSummationOptions& options,
                                    const ProgressCallback& progress = no_progress());

// The value itself, f_fabric(w_o, w_i) per channel (for tests and for tabulating elsewhere).
void fabric_sum(const TabulatedBsdfTable& fiber, const FabricSummationOptions& options,
                const Vec3& wo, const Vec3& wi, std::span<double> out);

}  // namespace weft
