// Cook-Torrance: microfacet identities, Fresnel limits, reciprocity, sample/pdf consistency and
// energy bounds.
#include <gtest/gtest.h>

#include <cmath>

#include "chi2.h"
#include "weft/core/rng.h"
#include "weft/materials/bsdfs.h"

using namespace weft;
using namespace weft::testing;

namespace {

const MicrofacetModel kModels[] = {MicrofacetModel::kBeckmann, MicrofacetModel::kGgx};

// Unpolarized Fresnel reflectance of a smooth air -> n boundary, written out here independently
// of fresnel.h (Born and Wolf, Principles of Optics, sec. 1.5.2).
double fresnel_reference(double cos_i, double n) {
  const double sin_t = std::sqrt(1 - cos_i * cos_i) / n, cos_t = std::sqrt(1 - sin_t * sin_t);
  const double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  const double rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// Integral over the upper hemisphere of g(w) by the midpoint rule in (cos theta, phi).
template <class G>
double hemisphere_integral(G g, int n_mu = 2000, int n_phi = 256) {
  double sum = 0;
  for (int i = 0; i < n_mu; ++i) {
    const double mu = (i + 0.5) / n_mu, s = std::sqrt(1 - mu * mu);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = (j + 0.5) * 2 * kPi / n_phi;
      sum += g(Vec3{s * std::cos(phi), s * std::sin(phi), mu});
    }
  }
  return sum * (1.0 / n_mu) * (2 * kPi / n_phi);
}

}  // namespace

TEST(Microfacet, DistributionIsNormalizedInProjectedArea) {
  // int D(h) cos theta_h dw_h = 1 (Walter et al. 2007, eq. 4). Isotropic: a fine 1-D rule in
  // theta (substituting t = tan^2 keeps narrow lobes resolved).
  for (auto model : kModels)
    for (double alpha : {0.02, 0.1, 0.3, 1.0}) {
      const MicrofacetDistribution d{model, alpha};
      const int n = 400000;
      double sum = 0;
      for (int i = 0; i < n; ++i) {
        const double theta = (i + 0.5) * (kPi / 2) / n;
        sum += d.d(spherical_direction(theta, 0)) * std::cos(theta) * std::sin(theta);
      }
      EXPECT_NEAR(2 * kPi * sum * (kPi / 2) / n, 1.0, 1e-5)
          << microfacet_model_name(model) << " alpha " << alpha;
    }
}

TEST(Microfacet, SmithMaskingPreservesProjectedArea) {
  // The visible projected area of the microfacets equals that of the macro-surface:
  // int G1(wo) max(0, wo.h) D(h) dw_h = cos theta_o (Heitz 2014, JCGT 3(2), eq. 2 with Smith's
  // G1 = 1 / (1 + Lambda)). This checks Lambda (incl. Beckmann's erfc form) against D.
  for (auto model : kModels)
    for (double alpha : {0.1, 0.5, 1.0})
      for (double theta_o : {0.0, 0.7, 1.3, 1.5}) {
        const MicrofacetDistribution d{model, alpha};
        const Vec3 wo = spherical_direction(theta_o, 0.2);
        const double visible = hemisphere_integral(
            [&](const Vec3& h) { return d.g1(wo) * std::max(0.0, dot(wo, h)) * d.d(h); });
        EXPECT_NEAR(visible, wo.z, 2e-3 * std::max(wo.z, 0.1))
            << microfacet_model_name(model) << " alpha " << alpha << " theta_o " << theta_o;
      }
}

TEST(Microfacet, NormalSamplingDensityIsNormalized) {
  for (auto model : kModels)
    for (double alpha : {0.2, 0.7})
      for (double theta_o : {0.2, 1.2}) {
        const MicrofacetDistribution d{model, alpha};
        const Vec3 wo = spherical_direction(theta_o, -0.5);
        EXPECT_NEAR(hemisphere_integral([&](const Vec3& h) { return d.pdf_normal(wo, h); }), 1.0,
                    2e-3);
      }
}

TEST(CookTorrance, NormalIncidenceFresnelAndSmoothLimit) {
  // F0 = ((n - 1) / (n + 1))^2 = 0.047451 for cotton's n = 1.557 (Fresnel at normal incidence).
  EXPECT_NEAR(fresnel_reference(1.0, 1.557), sqr(0.557 / 2.557), 1e-15);
  // As alpha -> 0 the albedo tends to the smooth-surface Fresnel reflectance F(theta_o).
  for (auto model : kModels)
    for (double theta_o_deg : {0.0, 30.0, 60.0}) {
      const Bsdf ct = CookTorranceBsdf{{model, 0.005}, 1.557, Rgb(1.0)};
      const Vec3 wo = direction(deg_to_rad(theta_o_deg));
      const auto a = estimate_albedo(ct, wo, 20000, 7);
      EXPECT_NEAR(a.mean.r, fresnel_reference(wo.z, 1.557), 2e-3 + 4 * a.standard_error.r)
          << microfacet_model_name(model) << " theta_o " << theta_o_deg;
    }
}

TEST(CookTorrance, IsReciprocalOnBothSides) {
  Rng rng(11);
  for (auto model : kModels)
    for (double alpha : {0.05, 0.3, 0.9}) {
      const CookTorranceBsdf ct{{model, alpha}, 1.557, Rgb(0.9, 0.5, 0.2)};
      int nonzero = 0;
      for (int i = 0; i < 2000; ++i) {
        Vec3 a = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
        Vec3 b = equal_area_square_to_sphere({rng.uniform(), rng.uniform()});
        if (a.z * b.z < 0) b.z = -b.z;
        const Rgb fab = ct.eval(a, b), fba = ct.eval(b, a);
        EXPECT_NEAR(fab.g, fba.g, 1e-12 * std::max(1.0, fab.g));
        nonzero += fab.g > 1e-6;
      }
      EXPECT_GT(nonzero, 50) << "the pairs must exercise the lobe";
    }
}

TEST(CookTorrance, BackSideMirrorsFrontAndNoTransmission) {
  const CookTorranceBsdf ct{{MicrofacetModel::kGgx, 0.3}, 1.557, Rgb(1.0)};
  const Vec3 wo = direction(0.5, 0.1), wi = direction(0.9, 2.5);
  const Vec3 wo_b{wo.x, wo.y, -wo.z}, wi_b{wi.x, wi.y, -wi.z};
  EXPECT_DOUBLE_EQ(ct.eval(wo_b, wi_b).r, ct.eval(wo, wi).r);
  EXPECT_DOUBLE_EQ(ct.pdf(wo_b, wi_b), ct.pdf(wo, wi));
  EXPECT_EQ(ct.eval(wo, wi_b).r, 0.0);
  EXPECT_EQ(ct.pdf(wo, wi_b), 0.0);
}

TEST(CookTorrance, SampleWeightIsEvalCosOverPdf) {
  Rng rng(21);
  for (auto model : kModels)
    for (double alpha : {0.05, 0.3, 0.9})
      for (double theta : {0.1, 1.0, 1.48, 2.5}) {
        const Bsdf ct = CookTorranceBsdf{{model, alpha}, 1.557, Rgb(0.8, 0.6, 0.4)};
        const Vec3 wo = direction(theta, 0.7);
        int drawn = 0;
        for (int i = 0; i < 2000; ++i) {
          const auto s = ct.sample(wo, {rng.uniform(), rng.uniform()}, rng.uniform());
          if (!s) continue;
          ++drawn;
          EXPECT_GT(s->wi.z * wo.z, 0.0);
          EXPECT_NEAR(s->pdf, ct.pdf(wo, s->wi), 1e-9 * s->pdf);
          const Rgb expect = ct.eval(wo, s->wi) * (std::abs(s->wi.z) / ct.pdf(wo, s->wi));
          EXPECT_NEAR(s->weight.b, expect.b, 1e-9 * std::max(1.0, expect.b));
        }
        EXPECT_GT(drawn, 1000);
      }
}

TEST(CookTorrance, PdfIntegratesToAtMostOne) {
  // The pdf integrates to the probability that sample() returns a direction (< 1 where
  // reflected microfacet samples fall below the horizon) and never above 1.
  for (auto model : kModels)
    for (double alpha : {0.1, 0.5, 1.0})
      for (double theta : {0.0, 0.8, 1.45}) {
        const Bsdf ct = CookTorranceBsdf{{model, alpha}, 1.557, Rgb(1.0)};
        const Vec3 wo = direction(theta);
        const auto cells = SphericalGrid{}.integrate(bsdf_pdf(ct, wo));
        double total = 0;
        for (double c : cells) total += c;
        EXPECT_LE(total, 1.0 + 2e-3);
        Rng rng(3);
        int drawn = 0;
        const int n = 100000;
        for (int i = 0; i < n; ++i)
          drawn += ct.sample(wo, {rng.uniform(), rng.uniform()}, 0.5).has_value();
        const double frac = static_cast<double>(drawn) / n;
        EXPECT_NEAR(total, frac, 4 * std::sqrt(frac * (1 - frac) / n) + 2e-3)
            << microfacet_model_name(model) << " alpha " << alpha << " theta " << theta;
      }
}

TEST(CookTorrance, DirectionalAlbedoIsAtMostOne) {
  // With F <= 1 and single scattering only, no wo may reflect more than it receives.
  uint64_t seed = 40;
  for (auto model : kModels)
    for (double alpha : {0.05, 0.3, 1.0})
      for (double theta_deg : {0.0, 30.0, 60.0, 80.0, 89.0}) {
        const Bsdf ct = CookTorranceBsdf{{model, alpha}, 4.0, Rgb(1.0)};
        const auto a = estimate_albedo(ct, direction(deg_to_rad(theta_deg)), 20000, seed++);
        EXPECT_LE(a.mean.r, 1.0 + 4 * a.standard_error.r) << theta_deg;
      }
}
