#pragma once
// The fiber spec: what a fiber is made of, as a plain value. Parsed from JSON (file or bundled
// preset), validated field by field (errors name the file and the field path), and hashed
// canonically so caches and table headers can name the spec that produced them.
//
// JSON layout (keys required unless marked optional; unknown keys are errors; docs/fiber-spec.md):
// {
//   "name": "red-cotton",
//   "fiber_radius_um": 8.0,
//   "roughness": {"distribution": "beckmann" | "ggx", "alpha": 0.35},
//   "host": {"n": SPECTRAL, "absorption_per_um": SPECTRAL | "absorption_per_mm": SPECTRAL,
//            "dyes": [{"dye": "congo-red", "concentration_owf_percent": 2.0,
//                      "uptake_fraction": 0.8}]},
//   "species": [{"name": "air voids", "n": SPECTRAL, "k": SPECTRAL, "volume_fraction": 0.02,
//                "size": {"distribution": "monodisperse", "radius_um": 0.3} |
//                        {"distribution": "lognormal", "median_radius_um": 0.3, "sigma": 0.5}}],
//   "boundary": "smooth" | "rough-dielectric" (optional, default "smooth"),
//   "density_g_cm3": 1.38 (the fibre material's density: required with a dye recipe, which it
//                    turns from percent on weight into mol/L; otherwise optional, and the
//                    nonwoven generator turns an areal density into fibre length with it;
//                    hashed only through the recipe's mol/L),
//   "notes": "free text" (optional, not hashed)
// }
// boundary: "smooth" is the paper's model, a Cook-Torrance surface lobe whose complement is
// refracted at the smooth normal (and leaves with it); "rough-dielectric" makes the roughness a
// rough dielectric interface both ways, whose reflection is the surface part and whose refraction
// feeds the volume (rough_dielectric.h, docs/fiber-bsdf.md).
// host.absorption_* is optional (zero when absent); species may be empty. host.dyes is an optional
// dye recipe (dye.h: bundled dyes, percent on the weight of fibre, uptake_fraction optional,
// default 1) whose Beer-Lambert absorption adds to host.absorption_*.
// SPECTRAL is one of
//   - a number (the same in every band),
//   - an array of 33 numbers, one per band 390, 400, ..., 710 nm,
//   - {"points": [[wavelength_nm, value], ...]}: linearly interpolated, wavelengths strictly
//     increasing and covering 390-710 nm (no extrapolation).
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/fiber/dye.h"
#include "weft/fiber/mie.h"
#include "weft/materials/microfacet.h"

namespace weft {

struct ParticleSpecies {
  std::string name;
  Spectrum n{}, k{};  // particle refractive index n + i k per band (k >= 0)
  SizeDistribution size;
  double volume_fraction = 0;  // in [0, 0.74]
};

// How light crosses the fiber's surface (the spec's "boundary").
enum class FiberBoundary { kSmooth, kRoughDielectric };
// "smooth" / "rough-dielectric".
const char* fiber_boundary_name(FiberBoundary boundary);

struct FiberSpec {
  std::string name;
  double fiber_radius_um = 0;
  MicrofacetModel roughness_distribution = MicrofacetModel::kBeckmann;
  double roughness_alpha = 0;         // in (0, 1]
  Spectrum host_n{};                  // real refractive index of the fibre material
  Spectrum host_absorption_per_um{};  // absorption of the host as given, >= 0 (dyes not included)
  std::vector<DyeComponent> dyes;     // the dye recipe (empty: none)
  std::vector<ParticleSpecies> species;
  FiberBoundary boundary = FiberBoundary::kSmooth;
  double density_g_cm3 = 0;  // 0: not given (then there are no dyes)
};

// Textile fibre materials: polypropylene 0.91 to glass 2.6 g/cm3; 0.5-25 leaves room for metals.
inline constexpr double kMinFiberDensityGcm3 = 0.5, kMaxFiberDensityGcm3 = 25;

inline constexpr double kMaxVolumeFraction = 0.74;  // close packing of equal spheres

// Physical bounds of a spec, checked when it is read: beyond them the physics does not hold and
// the work (Mie series, photon walks) grows without limit (a median radius of 1e4 um, a host index
// of 1e6 or 1000 species each ran for hours).
// Textile fibres: microfibres are about 1 um in radius, cotton 6-10 um, PET 6 um (docs/presets.md),
// coarse monofilaments about 100 um; 0.5-500 um covers them all.
inline constexpr double kMinFiberRadiusUm = 0.5, kMaxFiberRadiusUm = 500;
// A fibre's host is a polymer or a glass: n 1.3-1.8 for polymers (docs/presets.md: cellulose
// 1.557, PET 1.60, wax 1.47); 3 leaves room for high-index glasses.
inline constexpr double kMinHostIndex = 1.0, kMaxHostIndex = 3.0;
// Inclusions: metals have n below 1 and k up to about 10 in the visible, rutile TiO2 n = 3.0
// (docs/presets.md), silicon 5.6 at 400 nm.
inline constexpr double kMaxParticleIndex = 10, kMaxParticleK = 20;
// Presets have one or two species (pigment, voids, wax, delustrant).
inline constexpr int kMaxSpecies = 16;
// The medium treats particles as small scatterers spread through the fibre: the volume-weighted
// median radius (the radius for monodisperse, median x exp(3 sigma^2) for lognormal) may be at
// most this share of the fibre radius.
inline constexpr double kMaxParticleShareOfFiberRadius = 0.5;

// The host's absorption coefficient per um: host_absorption_per_um plus the dye recipe's.
Spectrum host_total_absorption_per_um(const FiberSpec& spec);

// Parses a spec from JSON text; 'file' names the source in error messages.
FiberSpec parse_fiber_spec(const std::string& json_text, const std::string& file);
// Loads a spec from a file path, or from a bundled preset by name when no such file exists.
// Errors: missing file (naming it and listing the presets), invalid JSON, invalid fields.
FiberSpec load_fiber_spec(const std::string& path_or_preset);

// Bundled presets (fiber/presets/*.json, docs/presets.md), compiled in.
std::vector<std::string> fiber_preset_names();
// The preset's JSON text; throws weft::Error listing the valid names for an unknown one.
const std::string& fiber_preset_json(const std::string& name);

// Canonical JSON of the parsed spec (sorted keys, spectra resolved to 33 band values, shortest
// round-trip numbers; a recipe's dyes by name, mol/L and molar absorption per band); the name and
// notes are left out, so two specs with the same physics hash
// alike however they were written.
std::string canonical_json(const FiberSpec& spec);
// FNV-1a 64 of canonical_json(spec), and the same as 16 lower-case hex digits.
uint64_t fiber_spec_hash(const FiberSpec& spec);
std::string fiber_spec_hash_hex(const FiberSpec& spec);

}  // namespace weft
