#pragma once
// One band of a fiber as the bakers see it: the rough surface seen from outside and the interior
// (its cylinder, index and photon transport), and the one routine by which light enters it. Both
// the direct route and the BSSRDF (fiber_bake.h, bssrdf.h) launch every photon through
// enter_fiber, so they share geometry, boundary and books by construction.
//
// Frames (docs/fiber-bsdf.md): the fiber's axis is the world x axis (transport.h); the surface
// point at angle phi has the frame CylinderGeometry::cylinder_frame(phi), local (x, y, z) =
// (axis t, binormal b, outward normal n).
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "weft/core/names.h"
#include "weft/core/rng.h"
#include "weft/core/vec.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/rough_dielectric.h"
#include "weft/fiber/transport.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/microfacet.h"

namespace weft {

// Receives each photon leaving the fiber (interior exits as the transport reports them; the
// surface lobe's reflection at the entry point).
using ExitSink = std::function<void(const ExitEvent&)>;

// The rough surface seen from outside, in the local frame of the hit point (z = normal).
struct FiberSurfaceModel {
  // Samples the surface-reflected direction for light from 'w_light' (z > 0): returns false if
  // none; else sets the reflected direction and its weight f * cos / pdf.
  std::function<bool(const Vec3& w_light, Vec2 u, double u_lobe, Vec3* w_out, double* weight)>
      sample;
  // Directional albedo of the surface lobe for light at cos theta (its complement enters).
  std::function<double(double cos_theta)> albedo;
  // Lobe directions drawn per photon, each carrying 1/samples of the sampled weight: the surface
  // part of a table is about half its noise, and a draw costs far less than the photon's transport.
  int samples = 1;
};

// The inside of the fiber: its cylinder (radius, index outside), the index inside, and a tracer
// for a photon just refracted in at surface point p (world frame) travelling along unit d with
// weight w. The tracer reports exits to the sink and returns its books (exited, absorbed,
// roulette, lost, scatterings; launched = w).
struct FiberInterior {
  CylinderGeometry geometry{1, 1};
  double n_inside = 1;
  std::function<PhotonTally(const Vec3& p, const Vec3& d, double w, Rng& rng, const ExitSink& sink)>
      trace;

  // Photon transport in the homogeneous medium of 'transport' (geometry and index from it).
  static FiberInterior transport(std::shared_ptr<const CylinderTransport> transport);
};

struct FiberBandPhysics {
  FiberSurfaceModel surface;
  FiberInterior interior;
  // A rough dielectric boundary (the spec's "rough-dielectric"): when set, entry is one draw of
  // its microsurface walk (reflected: the surface part; refracted: the volume part) and 'surface'
  // is unused; the interior's transport exits through the same interface.
  std::shared_ptr<const RoughDielectricInterface> boundary;

  // Throws weft::Error naming the field (n_inside, surface, trace).
  void validate() const;
};

// A smooth dielectric boundary both ways (Fresnel reflection at entry, sampled as the mirror
// direction; smooth Fresnel at exits): the setting of the paper's BSSRDF and of the transport
// engine's own launch_external.
FiberBandPhysics smooth_fiber_physics(const TransportMedium& medium, double radius,
                                      double n_outside, TransportOptions options = {});

// How the interior's exits are tallied: one by one as photons leave (plain), or by next-event
// estimation at every flight's start (TransportOptions::expected_exits; smooth boundary only).
// Both are unbiased estimates of the same table (docs/fiber-bsdf.md).
enum class FiberExitEstimator : uint8_t { kPlain, kNextEvent };
inline constexpr NameTable<FiberExitEstimator, 2> kFiberExitEstimators = {{
    {FiberExitEstimator::kPlain, "plain", "plain exits"},
    {FiberExitEstimator::kNextEvent, "nee", "next-event estimation"},
}};
const char* fiber_exit_estimator_name(FiberExitEstimator e);  // "plain", "nee"
// Parses a name of kFiberExitEstimators; weft::Error naming 'field' otherwise.
FiberExitEstimator parse_fiber_exit_estimator(const std::string& name, const std::string& field);

// One band of a spec. Boundary "smooth": the Cook-Torrance surface lobe at the band's host index,
// the rough boundary both ways (light leaving the fiber is transmitted with 1 - the lobe's albedo
// at the outside angle, as on entry, which keeps the fiber reciprocal). Boundary
// "rough-dielectric": the rough dielectric interface of the spec's roughness at the band's host
// index, both ways. Then cylinder transport in the band's medium. 'albedo' (smooth only) may be
// shared between bands of equal host index; null computes it. 'mode': how the interior's transport
// treats absorption (transport.h); 'estimator': how its exits are tallied (Error with the
// rough-dielectric boundary and next-event estimation).
FiberBandPhysics fiber_band_physics(const FiberSpec& spec, const MediumBand& band,
                                    uint64_t max_events_per_photon = 10'000'000,
                                    std::shared_ptr<const SurfaceAlbedoTable> albedo = nullptr,
                                    WeightMode mode = WeightMode::implicit_capture,
                                    FiberExitEstimator estimator = FiberExitEstimator::kPlain);

// The interior's medium of one band, and the transport options that make light leave a fiber
// through the same boundary it entered by (the rough dielectric both ways, or the surface lobe's
// complement as the exit transmittance): fiber_band_physics builds its cylinder from them, and
// fiber cross-sections other than the round one (fiber_layer.h) build theirs the same way.
TransportMedium fiber_band_medium(const MediumBand& band);
TransportOptions fiber_band_transport_options(
    const FiberBandPhysics& fiber, uint64_t max_events_per_photon, WeightMode mode,
    FiberExitEstimator estimator = FiberExitEstimator::kPlain);

// Light from world direction 'omega' (towards the light) meets the fiber at surface angle phi
// (axial position 0) with flux weight w0. The surface lobe's sampled reflection goes to
// 'surface_exits' (may be empty; booked as specular and specular_excess either way); the rest,
// 1 - albedo, enters refracted at the smooth normal and is traced, its exits going to
// 'interior_exits' (required: Error if empty). With a rough dielectric boundary the photon either
// reflects off it (to 'surface_exits', booked as specular) or enters refracted by it, whole. Adds
// one launched photon to 'books'. Deterministic given rng. 'lobe_uniforms' (smooth boundary; may
// be empty: drawn from rng) holds the surface lobe's uniforms, 3 per sample (u, then u_lobe), as a
// stratified entry draws them (fiber_bake.h, FiberEntrySampling).
void enter_fiber(const FiberBandPhysics& fiber, double phi, const Vec3& omega, double w0, Rng& rng,
                 const ExitSink& surface_exits, const ExitSink& interior_exits, PhotonTally& books,
                 std::span<const double> lobe_uniforms = {});

}  // namespace weft
