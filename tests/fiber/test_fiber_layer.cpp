// The flattened-fiber experiment (fiber_layer.h): the elliptical cross-section's geometry, the
// layer's energy books, and the round fiber's entry and transport against the cylinder beam.
#include <gtest/gtest.h>

#include <cmath>

#include "transport_test_util.h"
#include "weft/core/rng.h"
#include "weft/fiber/elliptic_cylinder.h"
#include "weft/fiber/fiber_layer.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/transport_cylinder.h"

using namespace weft;
using weft::testing::within_sigma;

namespace {

FiberSpec synthetic_spec(FiberBoundary boundary) {
  FiberSpec spec;
  spec.name = "synthetic";
  spec.fiber_radius_um = 8;
  spec.roughness_alpha = 0.35;
  spec.boundary = boundary;
  return spec;
}

MediumBand synthetic_band(double mu_a, double mu_s) {
  MediumBand b;
  b.band = 0;
  b.host_n = 1.55;
  b.mu_a_per_um = mu_a;
  b.mu_s_per_um = mu_s;
  b.phase = PhaseFunction::henyey_greenstein(0.5);
  return b;
}

FiberLayerSettings small_layer(double aspect, uint64_t photons) {
  return {.aspect = aspect,
          .rows = 4,
          .fibers_per_row = 4,
          .pitch_um = 34,
          .tilt_spread_deg = 20,
          .photons_per_band = photons,
          .threads = 2};
}

}  // namespace

TEST(EllipticCylinder, AtAspectOneItIsTheRoundCylinder) {
  const EllipticCylinderGeometry e(3, 3, 1);
  const CylinderGeometry c(3, 1);
  Rng rng(7);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 p{rng.uniform(), 2.9 * (2 * rng.uniform() - 1), 2 * (2 * rng.uniform() - 1)};
    if (!c.contains(p)) continue;
    const Vec3 d = normalize(Vec3{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5});
    EXPECT_TRUE(e.contains(p));
    EXPECT_NEAR(e.distance_to_boundary(p, d).distance, c.distance_to_boundary(p, d).distance,
                1e-12);
    const Vec3 w = c.snap(p, 0);
    EXPECT_NEAR(length(e.outward_normal(w, 0) - c.outward_normal(w, 0)), 0, 1e-12);
    EXPECT_NEAR(length(e.snap(p, 0) - w), 0, 1e-12);
  }
}

TEST(EllipticCylinder, MeetsItsWallAtItsSemiAxes) {
  const EllipticCylinderGeometry e(4, 1, 1);
  EXPECT_NEAR(e.distance_to_boundary({0, 0, 0}, {0, 1, 0}).distance, 4, 1e-12);
  EXPECT_NEAR(e.distance_to_boundary({0, 0, 0}, {0, 0, -1}).distance, 1, 1e-12);
  // 45 degrees: (t / sqrt 2)^2 (1/16 + 1) = 1.
  EXPECT_NEAR(e.distance_to_boundary({5, 0, 0}, normalize(Vec3{0, 1, 1})).distance,
              std::sqrt(2.0 / (1.0 / 16 + 1)), 1e-12);
  const Vec3 n = e.outward_normal(e.snap({0, 3, 0.5}, 0), 0);
  EXPECT_NEAR(length(n), 1, 1e-12);
  EXPECT_GT(n.z / n.y, 0.5 / 3);  // the flat side's normal turns towards z
}

TEST(FiberLayer, FibersNeverOverlap) {
  for (double aspect : {1.0, 3.0}) {
    const FiberLayerSettings s = small_layer(aspect, 1);
    const std::vector<LayerFiber> f = fiber_layer_fibers(s, 8);
    const double period = s.fibers_per_row * s.pitch_um, a = 8 * std::sqrt(aspect);
    // Points on each wall (and its images) must lie outside every other fiber.
    for (size_t i = 0; i < f.size(); ++i)
      for (int k = 0; k < 64; ++k) {
        const double phi = 2 * kPi * k / 64, c = std::cos(f[i].tilt_rad),
                     s2 = std::sin(f[i].tilt_rad);
        const double ly = a * std::cos(phi), lz = (8 / std::sqrt(aspect)) * std::sin(phi);
        const double y = f[i].y_um + c * ly - s2 * lz, z = f[i].z_um + s2 * ly + c * lz;
        for (size_t j = 0; j < f.size(); ++j) {
          if (j == i) continue;
          for (int m = -1; m <= 1; ++m) {
            const double cj = std::cos(f[j].tilt_rad), sj = std::sin(f[j].tilt_rad);
            const double dy = y - f[j].y_um - m * period, dz = z - f[j].z_um;
            const double qy = cj * dy + sj * dz, qz = -sj * dy + cj * dz;
            EXPECT_GT(sqr(qy / a) + sqr(qz * std::sqrt(aspect) / 8), 1.0) << i << " in " << j;
          }
        }
      }
  }
}

// A lossless fiber (no absorption) behind a rough dielectric returns every photon with weight 1:
// reflected + transmitted = 1 to rounding, nothing lost, round and flattened alike.
TEST(FiberLayer, ALosslessLayerReturnsAllTheLight) {
  const FiberSpec spec = synthetic_spec(FiberBoundary::kRoughDielectric);
  for (double aspect : {1.0, 3.0}) {
    const FiberLayerBandResult r =
        simulate_fiber_layer_band(spec, synthetic_band(0, 0.05), small_layer(aspect, 4000));
    EXPECT_NEAR(r.reflected.mean + r.transmitted.mean, 1, 1e-12) << aspect;
    EXPECT_EQ(r.lost.mean, 0) << aspect;
    EXPECT_EQ(r.absorbed.mean, 0) << aspect;
    EXPECT_GT(r.reflected.mean, 0.05) << aspect;
    EXPECT_GT(r.transmitted.mean, 0.05) << aspect;
    EXPECT_NEAR(r.energy_imbalance, 0, 1e-12);
  }
}

// With the smooth boundary the surface lobe is sampled (weight f cos / pdf over the tabulated
// albedo), so the returned light is 1 only within the noise of that excess.
TEST(FiberLayer, ALosslessLayerWithTheSurfaceLobeReturnsAllTheLightWithinNoise) {
  const FiberSpec spec = synthetic_spec(FiberBoundary::kSmooth);
  for (double aspect : {1.0, 3.0}) {
    const FiberLayerBandResult r =
        simulate_fiber_layer_band(spec, synthetic_band(0, 0.05), small_layer(aspect, 4000));
    EXPECT_TRUE(within_sigma(r.surface_excess, 0, 4)) << aspect;
    EXPECT_NEAR(r.reflected.mean + r.transmitted.mean - r.surface_excess.mean, 1, 1e-9);
    EXPECT_EQ(r.lost.mean, 0);
    EXPECT_NEAR(r.energy_imbalance, 0, 1e-12);
  }
}

// One round fiber per period, one row: a vertical beam meets it over 2 R of every period P, and
// what it absorbs there is what the project's cylinder beam (transport_cylinder.h, the same
// medium, the same rough interface both ways) absorbs, independently estimated.
TEST(FiberLayer, ALoneRoundFiberAbsorbsWhatTheCylinderBeamAbsorbs) {
  const FiberSpec spec = synthetic_spec(FiberBoundary::kRoughDielectric);
  const MediumBand band = synthetic_band(0.02, 0.05);
  FiberLayerSettings s = small_layer(1, 40000);
  s.rows = 1;
  s.fibers_per_row = 1;
  s.pitch_um = 64;
  const FiberLayerBandResult layer = simulate_fiber_layer_band(spec, band, s);
  const FiberBandPhysics physics = fiber_band_physics(spec, band);
  CylinderBeamSetup beam{
      .medium = fiber_band_medium(band),
      .radius = 8,
      .n_outside = 1,
      .direction = {0, 0, -1},
      .options = fiber_band_transport_options(physics, 10'000'000, WeightMode::implicit_capture)};
  const CylinderBeamResult ref =
      simulate_cylinder_beam(beam, weft::testing::batch_options(40000, 3, 2, 1024));
  const double coverage = 16.0 / 64;
  const MeanEstimate per_fiber{layer.absorbed.mean / coverage, layer.absorbed.std_error / coverage};
  EXPECT_GT(ref.absorbed.mean, 0.1);
  EXPECT_TRUE(within_sigma(per_fiber, ref.absorbed.mean, 4, ref.absorbed.std_error));
}

TEST(FiberLayer, BadSettingsNameTheirField) {
  FiberLayerSettings s;
  s.aspect = 0.5;
  EXPECT_NE(weft::testing::error_of([&] { s.validate(8); }).find("aspect"), std::string::npos);
  s.aspect = 5;
  s.pitch_um = 20;  // narrower than a 5:1 ribbon of radius 8 (35.8 um wide)
  EXPECT_NE(weft::testing::error_of([&] { s.validate(8); }).find("pitch_um"), std::string::npos);
}
