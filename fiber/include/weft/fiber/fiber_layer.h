#pragma once
// An experiment (docs/fabric-bsdf.md, "Flattened fibers: an experiment"): light at normal
// incidence on a layer of parallel fibers lying in the cloth's plane, round or flattened
// (elliptical cross-section of the round fiber's area), traced with the fiber's own physics and
// no fiber table: photon transport in the band's medium inside every fiber (transport.h, on an
// EllipticCylinderGeometry), the spec's surface at every crossing (its rough dielectric, or its
// Cook-Torrance lobe whose complement enters), straight flight in air between fibers. Round and
// flattened fibers take one code path; a lossless fiber returns all the light.
//
// Geometry: the fibers run along x; the cross-section plane is (y, z), z the cloth's normal, the
// layer below z = 0, periodic in y with period fibers_per_row * pitch_um. The layer is `rows` rows
// of fibers_per_row fibers each; within a row each fiber keeps to its own cell of width pitch_um,
// jittered inside it, each row shifted at random, so fibers never overlap. A flattened fiber's
// long axis lies in the cloth's plane, tilted uniformly within +-tilt_spread_deg (a ribbon's
// twist and a yarn's curvature turn it). Same rows and pitch for every aspect: the same fibers
// and the same mass per cloth area.
//
// Every band draws the same random numbers and carries absorption as a weight (transport.h,
// WeightMode::absorption_weight), so bands walk the same paths as far as their scattering allows:
// the reduction to RGB subtracts bands (a red cloth's green is a small difference of large band
// values), and correlated band errors largely cancel there. So the RGB values carry no error of
// their own; independent seeds give it (weft bench flatten --batches).
//
// Output per band: the radiance coefficient beta = pi f of the layer at normal incidence,
// averaged over the azimuth (what the isotropic average of in-plane curves gives at theta_i = 0),
// in rings of view zenith angle, reflected (above) and transmitted (below), with standard errors.
#include <cstdint>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/transport_batch.h"

namespace weft {

struct FiberLayerSettings {
  double aspect = 1;           // width : thickness of the cross-section (1: round), >= 1
  int rows = 11;               // rows of fibers, one above the other
  int fibers_per_row = 8;      // per period
  double pitch_um = 34;        // centre to centre within a row (mean)
  double tilt_spread_deg = 0;  // long axis within +- this of the cloth's plane, in [0, 90]
  // The patch the layer stands for, tilted per photon (a facet model: no shadowing between
  // patches): the fibers' axes out of the cloth's plane by up to crimp_deg (a crimped yarn), the
  // patch about the fibers' axes by up to yarn_tilt_deg (a round yarn's flanks).
  double crimp_deg = 0;
  double yarn_tilt_deg = 0;
  int rings = 18;  // view zenith rings over [0, 90] degrees, equal in angle
  uint64_t photons_per_band = 20000;
  uint64_t seed = 1;
  int threads = 0;

  void validate(double fiber_radius_um) const;  // weft::Error naming the field
};

// One fiber of the layer: its axis' (y, z) and its long axis' tilt from the y axis.
struct LayerFiber {
  double y_um = 0, z_um = 0, tilt_rad = 0;
};

// The layer's fibers for these settings (from settings.seed), and its period along y.
std::vector<LayerFiber> fiber_layer_fibers(const FiberLayerSettings& settings,
                                           double fiber_radius_um);

struct FiberLayerBandResult {
  std::vector<MeanEstimate> reflected_beta;               // per ring
  std::vector<MeanEstimate> transmitted_beta;             // per ring
  MeanEstimate reflected, transmitted;                    // fractions of the incident power
  MeanEstimate absorbed, lost, roulette, surface_excess;  // the rest of the books (excess: mean 0)
  double energy_imbalance = 0;  // 1 - (reflected + transmitted + absorbed + lost + roulette
                                //      - surface_excess): zero up to rounding
  uint64_t photons = 0, fiber_crossings = 0;
};

// One band of the spec's medium (band.band names it).
FiberLayerBandResult simulate_fiber_layer_band(const FiberSpec& spec, const MediumBand& band,
                                               const FiberLayerSettings& settings);

struct FiberLayerResult {
  std::vector<FiberLayerBandResult> bands;  // in the medium's order
  // Linear sRGB under D65 (bands_to_linear_srgb) of beta per ring; only when the medium holds
  // all kNumBands bands.
  std::vector<Rgb> reflected_beta, transmitted_beta;
  Rgb reflected, transmitted;
};

// Every band of 'medium' (its bands from build_fiber_medium of the same spec).
FiberLayerResult simulate_fiber_layer(const FiberSpec& spec, const FiberMedium& medium,
                                      const FiberLayerSettings& settings);

}  // namespace weft
