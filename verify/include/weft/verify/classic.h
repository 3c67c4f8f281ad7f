#pragma once
// The classic baseline's fiber from a baked fiber table given in place of a spec (weft verify
// --fiber TABLE): its diffuse colour and its roughness. The classic fiber itself and its fiber
// table are materials/classic_fiber.h's.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/classic_fiber.h"
#include "weft/materials/microfacet.h"

namespace weft {

// The volume albedo of a fiber table alone (what stands for a bake's exit - surface fraction), per
// channel of the table: the table's total albedo minus that of the classic fiber's own
// Cook-Torrance lobe (diffuse colour 0,
// tabulated by classic_fiber_table at R = 16, 4 samples per cell pair); divided by
// classic_entering_fraction it is the reflectance with which the classic fiber sends out as much
// light in all as the table's fiber. For a table baked from a spec this stands
// for the volume albedo exit_fraction - surface_fraction: the lobe's albedo and the bake's surface
// fraction are those of the same rough surface (docs/verify.md gives the figures). Channels may
// come out negative (a table darker than its surface alone); the caller decides.
std::vector<double> classic_diffuse_from_fiber_table(const TabulatedBsdfTable& fiber,
                                                     const MicrofacetDistribution& d, double ior,
                                                     uint64_t seed, int threads);

// The share of the light hitting a classic fiber that gets past its Cook-Torrance lobe,
// 1 - E_avg (E_avg: the untinted lobe's albedo averaged over incident directions,
// SpecularAlbedoTable::average). A classic fiber of reflectance rho sends out E_avg + rho (1 -
// E_avg) of the light hitting it (ClassicFiberBsdf), so the reflectance that stands for a fiber
// whose volume part returns V of all the light (the bake's exit - surface fraction, or
// classic_diffuse_from_fiber_table) is V / (1 - E_avg): with V itself the classic fiber is darker
// than the fiber it stands for by E_avg (5-7 % for cotton's Beckmann 0.35, n 1.557).
double classic_entering_fraction(const MicrofacetDistribution& d, double ior);

// The fiber surface's roughness that a fiber table's header states ("roughness": "beckmann alpha
// 0.350000", as weft bake fiber writes it); nullopt when the header has none; weft::Error naming
// 'file' and "roughness" when it is malformed or out of (0, 1].
std::optional<MicrofacetDistribution> fiber_table_roughness(const TabulatedBsdfTable& table,
                                                            const std::string& file);

}  // namespace weft
