// The paper's classic fiber (Cook-Torrance + Lambert coupled by the energy the surface leaves).
#include <gtest/gtest.h>

#include <cmath>

#include "chi2.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdfs.h"

using namespace weft;
using namespace weft::testing;

namespace {
const MicrofacetDistribution kDistributions[] = {{MicrofacetModel::kBeckmann, 0.1},
                                                 {MicrofacetModel::kBeckmann, 0.5},
                                                 {MicrofacetModel::kGgx, 0.2},
                                                 {MicrofacetModel::kGgx, 1.0}};
}

TEST(ClassicFiber, SpecularAlbedoTableMatchesMonteCarlo) {
  // E(mu) is tabulated by a deterministic midpoint rule; compare with an independent random
  // estimate of the Cook-Torrance albedo.
  uint64_t seed = 1;
  for (const auto& d : kDistributions) {
    const auto fiber = ClassicFiberBsdf::create(Rgb(0.5), d);
    const Bsdf ct = fiber.surface;
    for (double mu : {0.05, 0.3, 0.62, 0.9, 1.0}) {
      const auto a = estimate_albedo(ct, {std::sqrt(1 - mu * mu), 0, mu}, 40000, seed++);
      EXPECT_NEAR((*fiber.surface_albedo)(mu), a.mean.r, 4 * a.standard_error.r + 1e-3)
          << microfacet_model_name(d.model) << " alpha " << d.alpha << " mu " << mu;
    }
  }
}

TEST(ClassicFiber, WhiteFurnaceWithLosslessVolume) {
  // reflectance = 1: the volume takes exactly the energy the surface leaves, so the directional
  // albedo is 1 for every wo (derivation in classic_fiber.h), up to the tabulation of E.
  uint64_t seed = 10;
  for (const auto& d : kDistributions) {
    const Bsdf fiber = ClassicFiberBsdf::create(Rgb(1.0), d);
    for (double theta_deg : {0.0, 30.0, 60.0, 80.0, 88.0, 150.0}) {
      const auto a = estimate_albedo(fiber, direction(deg_to_rad(theta_deg)), 40000, seed++);
      EXPECT_NEAR(a.mean.g, 1.0, 4 * a.standard_error.g + 2e-3)
          << microfacet_model_name(d.model) << " alpha " << d.alpha << " theta " << theta_deg;
    }
  }
}

TEST(ClassicFiber, AlbedoIsSurfacePlusReflectanceTimesRemainder) {
  const Rgb rho(0.8, 0.3, 0.05);
  uint64_t seed = 20;
  for (const auto& d : kDistributions) {
    const auto fiber = ClassicFiberBsdf::create(rho, d);
    for (double theta_deg : {10.0, 70.0}) {
      const Vec3 wo = direction(deg_to_rad(theta_deg));
      const double e = (*fiber.surface_albedo)(wo.z);
      const auto a = estimate_albedo(fiber, wo, 40000, seed++);
      EXPECT_NEAR(a.mean.r, e + rho.r * (1 - e), 4 * a.standard_error.r + 2e-3);
      EXPECT_NEAR(a.mean.b, e + rho.b * (1 - e), 4 * a.standard_error.b + 2e-3);
    }
  }
}

TEST(ClassicFiber, VolumePartIntegratesToTheRemainder) {
  // int (1 - E(mu_i)) cos / pi dw_i = 1 - E_avg exactly for the interpolated E: midpoint rule in
  // mu.
  const auto fiber = ClassicFiberBsdf::create(Rgb(1.0), {MicrofacetModel::kGgx, 0.4});
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double mu = (i + 0.5) / n;
    sum += (1 - (*fiber.surface_albedo)(mu)) * 2 * mu / n;
  }
  EXPECT_NEAR(sum, 1 - fiber.surface_albedo->average, 1e-8);
}

TEST(ClassicFiber, BlackVolumeIsCookTorrance) {
  const auto fiber = ClassicFiberBsdf::create(Rgb(0.0), {MicrofacetModel::kBeckmann, 0.3});
  const Vec3 wo = direction(0.4), wi = direction(1.0, 2.0);
  EXPECT_DOUBLE_EQ(fiber.eval(wo, wi).r, fiber.surface.eval(wo, wi).r);
  EXPECT_DOUBLE_EQ(fiber.pdf(wo, wi), fiber.surface.pdf(wo, wi));
}

TEST(ClassicFiber, ReciprocalAndConsistentSampling) {
  Rng rng(5);
  const Bsdf fiber = ClassicFiberBsdf::create(Rgb(0.7, 0.2, 0.1), {MicrofacetModel::kGgx, 0.25});
  for (int i = 0; i < 2000; ++i) {
    const Vec3 a = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    Vec3 b = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
    if (a.z * b.z < 0) b.z = -b.z;
    EXPECT_NEAR(fiber.eval(a, b).r, fiber.eval(b, a).r, 1e-12 * std::max(1.0, fiber.eval(a, b).r));
    const auto s = fiber.sample(a, {rng.uniform(), rng.uniform()}, rng.uniform());
    if (!s) continue;
    EXPECT_NEAR(s->pdf, fiber.pdf(a, s->wi), 1e-9 * s->pdf);
    const Rgb expect = fiber.eval(a, s->wi) * (std::abs(s->wi.z) / fiber.pdf(a, s->wi));
    EXPECT_NEAR(s->weight.r, expect.r, 1e-9 * std::max(1.0, expect.r));
  }
}

TEST(ClassicFiber, PdfIntegratesToAtMostOne) {
  const Bsdf fiber = ClassicFiberBsdf::create(Rgb(0.5), {MicrofacetModel::kBeckmann, 0.3});
  for (double theta : {0.2, 1.4}) {
    double total = 0;
    for (double c : SphericalGrid{}.integrate(bsdf_pdf(fiber, direction(theta)))) total += c;
    EXPECT_LE(total, 1.0 + 2e-3);
    // ... and equals the probability that sample() returns a direction (Beckmann's D cos
    // sampling loses the normals that reflect below the horizon).
    Rng rng(9);
    int drawn = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i)
      drawn +=
          fiber.sample(direction(theta), {rng.uniform(), rng.uniform()}, rng.uniform()).has_value();
    const double frac = static_cast<double>(drawn) / n;
    EXPECT_NEAR(total, frac, 4 * std::sqrt(frac * (1 - frac) / n) + 2e-3);
  }
}
