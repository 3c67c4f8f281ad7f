// The rough dielectric interface (rough_dielectric.h): its microsurface walk against the
// single-scattering microfacet BSDF computed by quadrature, the smooth (Fresnel) limit, energy
// conservation, and the grazing entry that motivated it (docs/fiber-bsdf.md).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "transport_test_util.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/rough_dielectric.h"
#include "weft/fiber/transport_cylinder.h"
#include "weft/materials/fresnel.h"

using namespace weft;

namespace {

constexpr double kCellulose = 1.557;  // cotton's index (docs/presets.md)

Vec3 at_cos(double c) {
  return {safe_sqrt(1 - c * c), 0, c};
}

// Fractions of 'n' photons from the light direction w (w.z > 0, above the side 'from_inside'
// mirrors) that the walk sends back to the light's side and through, and the same for walks of
// one step only.
struct WalkFractions {
  double reflected = 0, transmitted = 0, reflected_1 = 0, transmitted_1 = 0;
  int lost = 0;
};
WalkFractions walk_fractions(const RoughDielectricInterface& rd, const Vec3& w, bool from_inside,
                             int n, uint64_t seed) {
  Rng rng(seed);
  WalkFractions f;
  const Vec3 d = from_inside ? Vec3{-w.x, -w.y, w.z} : -w;  // travelling
  for (int k = 0; k < n; ++k) {
    const RoughDielectricScatter s = rd.scatter(d, rng);
    f.lost += s.lost;
    const bool back = s.outside != from_inside;
    EXPECT_NEAR(length_squared(s.direction), 1, 1e-12);
    EXPECT_EQ(s.outside, s.direction.z > 0);
    (back ? f.reflected : f.transmitted) += 1.0 / n;
    if (s.order == 1) (back ? f.reflected_1 : f.transmitted_1) += 1.0 / n;
  }
  return f;
}

// Binomial standard error of a fraction p from n draws (at least that of one count in n).
double binomial_se(double p, int n) {
  return std::sqrt(std::max(p * (1 - p), 1.0 / n) / n);
}

}  // namespace

TEST(RoughDielectric, FirstStepIsTheSingleScatteringMicrofacetBsdf) {
  // The walk's one-step paths are the microfacet BSDF of Walter et al. 2007 with height-correlated
  // masking (Heitz et al. 2016, sec. 5): R1 = int F D G2 / (4 cos_i cos_o) cos_o, T1 the same for
  // refraction with G2 = B(1 + Lambda_i, 1 + Lambda_o). The quadrature uses only D and Lambda;
  // the walk samples heights and visible normals (Heitz 2018, Heitz and d'Eon 2014), so this checks
  // the samplers. Both distributions, both sides (total internal reflection from inside).
  const int n = 40000;
  uint64_t seed = 11;
  for (const MicrofacetModel model : {MicrofacetModel::kBeckmann, MicrofacetModel::kGgx})
    for (const double alpha : {0.35, 0.8}) {
      const RoughDielectricInterface rd(model, alpha, 1.0, kCellulose);
      for (const bool inside : {false, true})
        for (const double c : {0.9, 0.3, 0.01}) {
          const RoughDielectricAlbedo a = rd.single_scatter_albedo(at_cos(c), inside);
          const WalkFractions f = walk_fractions(rd, at_cos(c), inside, n, ++seed);
          const std::string where = std::string(microfacet_model_name(model)) + " alpha " +
                                    std::to_string(alpha) + (inside ? " inside" : " outside") +
                                    " cos " + std::to_string(c);
          // 4.5 standard errors, plus the quadrature's own error (1e-4 at these nodes).
          EXPECT_NEAR(f.reflected_1, a.reflected, 4.5 * binomial_se(a.reflected, n) + 1e-4)
              << where;
          EXPECT_NEAR(f.transmitted_1, a.transmitted, 4.5 * binomial_se(a.transmitted, n) + 1e-4)
              << where;
          // Energy: every photon leaves, on one side or the other.
          EXPECT_EQ(f.lost, 0) << where;
          EXPECT_NEAR(f.reflected + f.transmitted, 1.0, 1e-9) << where;
          // Single scattering loses what the further steps carry (more at grazing, rough).
          EXPECT_LE(a.reflected + a.transmitted, 1 + 1e-4) << where;
        }
    }
}

TEST(RoughDielectric, SmoothLimitIsFresnelAndSnell) {
  // alpha -> 0: reflectance -> the smooth Fresnel reflectance, directions -> mirror and Snell.
  const int n = 20000;
  for (const MicrofacetModel model : {MicrofacetModel::kBeckmann, MicrofacetModel::kGgx}) {
    const RoughDielectricInterface rd(model, 1e-4, 1.0, kCellulose);
    Rng rng(5);
    for (const bool inside : {false, true})
      for (const double c : {1.0, 0.6, 0.2}) {
        const Vec3 w = at_cos(c);
        const double n_i = inside ? kCellulose : 1.0, n_t = inside ? 1.0 : kCellulose;
        double cos_t = 0;
        const double r = fresnel_dielectric(c, n_i, n_t, &cos_t);
        const Vec3 d = inside ? Vec3{-w.x, -w.y, w.z} : -w;
        double reflected = 0;
        int far = 0;
        for (int k = 0; k < n; ++k) {
          const RoughDielectricScatter s = rd.scatter(d, rng);
          const bool back = s.outside != inside;
          reflected += back ? 1.0 / n : 0.0;
          // The direction within a few alpha of the smooth one (worked out with the light above,
          // then mirrored when it is inside).
          const double eta = n_i / n_t;
          const Vec3 z{0, 0, 1};
          Vec3 expected = back ? -w + 2 * c * z : -eta * w + (eta * c - cos_t) * z;
          if (inside) expected.z = -expected.z;
          far += dot(s.direction, normalize(expected)) < 1 - 1e-5;
        }
        // Off by more than 4.5e-3 rad (45 alpha): never for Beckmann; GGX's long tail of slopes
        // (density ~ slope^-4) puts a few tenths of a percent there.
        EXPECT_LE(far, n / 100) << microfacet_model_name(model) << " cos " << c;
        EXPECT_NEAR(reflected, r, 4.5 * binomial_se(r, n))
            << microfacet_model_name(model) << " cos " << c << (inside ? " inside" : " outside");
      }
  }
}

TEST(RoughDielectric, GrazingEntryFollowsTheRoughInterface) {
  // Light at cos 0.01 on red cotton's surface (Beckmann, alpha 0.35, n 1.557). Smooth Fresnel
  // lets in 5.6 % and the paper's model (1 - Cook-Torrance albedo, refracted at the smooth normal)
  // 72 %. The rough interface lets in at least its single-scattering transmittance T1 and at most
  // 1 - R1 (quadrature, independent of the walk); enter_fiber with the rough boundary must land
  // there.
  const double c = 0.01;
  double cos_t = 0;
  const double smooth_in = 1 - fresnel_dielectric(c, 1.0, kCellulose, &cos_t);
  EXPECT_NEAR(smooth_in, 0.056, 0.001);
  const RoughDielectricInterface rd(MicrofacetModel::kBeckmann, 0.35, 1.0, kCellulose);
  const RoughDielectricAlbedo a = rd.single_scatter_albedo(at_cos(c));
  // Through enter_fiber (the one entry routine), with a dye so dark that the interior ends at
  // once: what enters is 1 - specular.
  const std::string json = R"({"name": "grazing", "fiber_radius_um": 8,
    "roughness": {"distribution": "beckmann", "alpha": 0.35}, "boundary": "rough-dielectric",
    "host": {"n": 1.557, "absorption_per_um": 1e4}, "species": []})";
  const FiberSpec spec = parse_fiber_spec(json, "grazing.json");
  const FiberBandPhysics ph = fiber_band_physics(spec, compute_medium_band(spec, 16));
  ASSERT_TRUE(ph.boundary);
  // At phi = pi/2 the normal is +z; the light comes from cos 0.01 off the horizon, across the axis.
  const Vec3 omega{0, -safe_sqrt(1 - c * c), c};
  PhotonTally books;
  Rng rng(9);
  const int n = 40000;
  const ExitSink none = [](const ExitEvent&) {};
  for (int k = 0; k < n; ++k) enter_fiber(ph, kPi / 2, omega, 1.0, rng, none, none, books);
  // Entered light needs somewhere to go: no interior sink is a caller's error, named.
  PhotonTally unused;
  EXPECT_THROW(enter_fiber(ph, kPi / 2, omega, 1.0, rng, none, ExitSink{}, unused), Error);
  const double entered = 1 - books.specular / books.launched;
  const double se = binomial_se(entered, n);
  EXPECT_GE(entered, a.transmitted - 4.5 * se);
  EXPECT_LE(entered, 1 - a.reflected + 4.5 * se);
  EXPECT_NEAR(books.imbalance(), 0, 1e-9);
  // Far from the smooth boundary's 5.6 %, and below the paper's model's 72 %.
  const double paper_in = 1 - SurfaceAlbedoTable(MicrofacetModel::kBeckmann, 0.35, kCellulose)(c);
  EXPECT_NEAR(paper_in, 0.72, 0.01);
  EXPECT_GT(entered, 3 * smooth_in);
  RecordProperty("entered", std::to_string(entered));
  RecordProperty("single_scatter_T1", std::to_string(a.transmitted));
  RecordProperty("single_scatter_R1", std::to_string(a.reflected));
  std::printf(
      "grazing cos %.2f: rough interface enters %.4f (T1 %.4f, 1 - R1 %.4f); smooth %.4f; "
      "paper's model %.4f\n",
      c, entered, a.transmitted, 1 - a.reflected, smooth_in, paper_in);
}

TEST(RoughDielectric, TransportEngineUsesItAtEntryAndExit) {
  // The transport engine's own external launch (simulate_cylinder_beam) with the rough interface
  // as its boundary: at alpha 1e-4 the beam's books match the smooth Fresnel boundary within
  // noise (an absorbing, scattering cylinder); rough, it conserves energy exactly.
  CylinderBeamSetup smooth;
  smooth.medium = weft::testing::hg_medium(0.02, 0.1, 0.8, kCellulose);
  smooth.radius = 10;
  smooth.direction = normalize(Vec3{0.3, 0, -1});
  const auto batch = weft::testing::batch_options(40000, 3, 2, 1000);
  const CylinderBeamResult a = simulate_cylinder_beam(smooth, batch);
  for (const double alpha : {1e-4, 0.5}) {
    auto rd = std::make_shared<const RoughDielectricInterface>(MicrofacetModel::kGgx, alpha, 1.0,
                                                               kCellulose);
    CylinderBeamSetup rough = smooth;
    rough.options.boundary_scatter = [rd](const Vec3& d, Rng& rng) {
      const RoughDielectricScatter s = rd->scatter(d, rng);
      return BoundaryScatter{s.direction, s.lost};
    };
    const CylinderBeamResult b = simulate_cylinder_beam(rough, batch);
    EXPECT_NEAR(b.energy_imbalance, 0, 1e-12) << alpha;
    EXPECT_EQ(b.lost.mean, 0.0) << alpha;
    if (alpha < 1e-3) {
      EXPECT_TRUE(
          weft::testing::within_sigma(b.specular, a.specular.mean, 4.5, a.specular.std_error));
      EXPECT_TRUE(
          weft::testing::within_sigma(b.absorbed, a.absorbed.mean, 4.5, a.absorbed.std_error));
    }
  }
  // The rough boundary replaces the exit reflectance: both at once is an error naming it.
  CylinderBeamSetup both = smooth;
  both.options.exit_reflectance = [](double) { return 0.1; };
  both.options.boundary_scatter = [](const Vec3& d, Rng&) { return BoundaryScatter{d}; };
  EXPECT_NE(weft::testing::error_of([&] {
              simulate_cylinder_beam(both, batch);
            }).find("boundary_scatter"),
            std::string::npos);
}
