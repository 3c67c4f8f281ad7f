#pragma once
// A weaving draft's thread colour as a dye of a base fiber (`weft bake fabric --thread-colours`,
// docs/fabric-bsdf.md "Thread colours"). A draft states a colour, not a dye, so the rule below
// makes a dye that gives the fibre that colour; it is an approximation: the cloth comes out darker
// and more saturated than the draft's swatch, since light crosses several fibres before it leaves.
//
// The rule:
// 1. The colour is sRGB-encoded (as drafts store it, components in [0, 1]); it is linearised
//    (IEC 61966-2-1).
// 2. Uplift to a smooth reflectance rho(lambda) on the 33 bands: three smooth blocks B_k (blue
//    below 490 nm, green between, red above 590 nm, raised-cosine edges 40 nm wide) that sum to 1
//    at every band; rho = 1 - sum_k d_k B_k, the darkness d = M^-1 (W (1 - rgb)), M the blocks'
//    linear sRGB under D65 (core/spectrum.h) and W that of the white reflector, so that rho's
//    colour under D65, white-balanced, is the thread's. M^-1 W has no negative entry, so d lies
//    in [0, 1] (to rounding, which is clipped) and rho in [0, 1] for every colour of the sRGB
//    cube: every thread colour is reproduced, saturated primaries included; white is rho = 1
//    exactly.
// 3. Absorption added to the base fiber's host: mu_a(lambda) = -ln(max(rho, kThreadMinReflectance))
//    / l per um, l = pi r / 2 the mean chord of the fibre's cross-section (Cauchy: pi area /
//    perimeter) for its radius r: one pass across the fibre along a mean chord transmits rho.
#include <array>
#include <string>

#include "weft/core/spectrum.h"
#include "weft/fiber/fiber_spec.h"

namespace weft {

// rho's floor: a black thread absorbs -ln(0.01) = 4.6 per mean chord, not infinitely.
inline constexpr double kThreadMinReflectance = 0.01;

struct ThreadDye {
  Spectrum reflectance{};        // rho per band
  Spectrum absorption_per_um{};  // mu_a per band, added to the base fiber's host
};

// The dye of an sRGB-encoded colour for a fibre of radius fiber_radius_um; weft::Error naming
// 'field' unless each component is finite and in [0, 1].
ThreadDye thread_dye(const std::array<double, 3>& srgb, double fiber_radius_um,
                     const std::string& field);

// 'base' with the dye's absorption added to its host's, named "<base> #rrggbb". White gives
// 'base' itself (its name and spec hash).
FiberSpec thread_colour_spec(const FiberSpec& base, const std::array<double, 3>& srgb,
                             const std::string& field);

// Block k of step 2 (0 red, 1 green, 2 blue) per band: the three sum to 1 at every band.
Spectrum thread_colour_block(int k);

// "#rrggbb" of a colour in [0, 1] (8 bits per component, rounded).
std::string srgb_hex(const std::array<double, 3>& srgb);

}  // namespace weft
