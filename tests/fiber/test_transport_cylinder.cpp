// Photon transport in the cylinder (fiber) geometry: geometry primitives, exact non-scattering
// results derived here by quadrature over the impact parameter, energy conservation,
// reproducibility and extremes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

#include "transport_test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fiber/transport_cylinder.h"
#include "weft/materials/fresnel.h"

using namespace weft;

namespace {

const auto medium = weft::testing::hg_medium;

CylinderBeamSetup beam(const TransportMedium& m, double radius, double n_out, const Vec3& dir) {
  return {.medium = m, .radius = radius, .n_outside = n_out, .direction = dir, .options = {}};
}

TaskBatch cylinder_batch(uint64_t photons, uint64_t seed, int threads = 2) {
  return weft::testing::batch_options(photons, seed, threads, 1024);
}

using weft::testing::within_sigma;

// Composite Simpson rule on [a, b] with n (even) intervals.
double simpson(const std::function<double(double)>& f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += f(a + i * h) * (i % 2 ? 4 : 2);
  return s * h / 3;
}

// Exact fate of a parallel beam on a non-scattering absorbing cylinder, averaged over the impact
// parameter b = r sin(psi) (db = r cos(psi) dpsi, which removes the square-root endpoints).
// For one impact parameter: Fresnel R at entry; inside, the refracted direction keeps its
// axial component scaled by eta = n_out / n_in, and every wall hit of a circle repeats the same
// angle of incidence, so each chord has the same length L = 2 r cos_t / |w'_perp|^2 and each
// internal hit the same reflectance R (Fresnel is symmetric). Summing the bounces:
//   exits = (1-R)^2 e^(-mu L) / (1 - R e^(-mu L)),  absorbed = (1-R)(1 - e^(-mu L)) / (...).
struct BeamFate {
  double specular = 0, exited = 0, absorbed = 0;
};
BeamFate non_scattering_cylinder(double mua, double r, double n_in, double n_out, const Vec3& w) {
  const double s = std::hypot(w.y, w.z);  // in-plane part of the beam direction
  const double eta = n_out / n_in;
  const double wx_in = eta * w.x;
  const double perp2_in = 1 - wx_in * wx_in;
  auto fate = [&](double psi, int which) {
    const double cos_i = s * std::cos(psi);
    double cos_t = cos_i;
    const double R = n_in == n_out ? 0.0 : fresnel_dielectric(cos_i, n_out, n_in, &cos_t);
    const double att = std::exp(-mua * 2 * r * cos_t / perp2_in);
    const double denom = 1 - R * att;
    const double v = which == 0   ? R
                     : which == 1 ? (1 - R) * (1 - R) * att / denom
                                  : (1 - R) * (1 - att) / denom;
    return 0.5 * v * std::cos(psi);  // (1 / 2r) * r cos(psi) dpsi
  };
  BeamFate out;
  out.specular = simpson([&](double p) { return fate(p, 0); }, -kPi / 2, kPi / 2, 20000);
  out.exited = simpson([&](double p) { return fate(p, 1); }, -kPi / 2, kPi / 2, 20000);
  out.absorbed = simpson([&](double p) { return fate(p, 2); }, -kPi / 2, kPi / 2, 20000);
  return out;
}

}  // namespace

TEST(TransportCylinder, FrameFollowsTheFiberConvention) {
  for (double phi : {0.0, 0.7, 2.5, -1.9}) {
    const Frame f = CylinderGeometry::cylinder_frame(phi);
    const CylinderGeometry g(2.0, 1.0);
    const Vec3 p = g.surface_point(phi, 0.3);
    EXPECT_NEAR(length(g.outward_normal(p, 0) - f.n), 0, 1e-15);
    EXPECT_EQ(f.s, (Vec3{1, 0, 0}));                       // t: the axis
    EXPECT_NEAR(length(cross(f.n, f.s) - f.t), 0, 1e-15);  // b = n x t
    EXPECT_NEAR(dot(f.s, f.n), 0, 1e-15);
  }
}

TEST(TransportCylinder, BoundaryDistances) {
  const CylinderGeometry g(1.0, 1.5);
  // From the centre every direction with no axial part travels exactly the radius.
  const auto h = g.distance_to_boundary({0, 0, 0}, normalize(Vec3{0, 0.6, 0.8}));
  EXPECT_NEAR(h.distance, 1.0, 1e-15);
  // An axial component stretches the path by 1 / sin(angle to the axis).
  EXPECT_NEAR(g.distance_to_boundary({5, 0, 0}, normalize(Vec3{1, 0, 1})).distance, std::sqrt(2.0),
              1e-14);
  // Along the axis: never.
  EXPECT_TRUE(std::isinf(g.distance_to_boundary({0, 0.5, 0}, {1, 0, 0}).distance));
  // On the wall, moving inwards: the full chord 2 cos(theta); moving outwards: zero.
  const Vec3 wall{0, 0, 1};
  const Vec3 in = normalize(Vec3{0, std::sin(0.3), -std::cos(0.3)});
  EXPECT_NEAR(g.distance_to_boundary(wall, in).distance, 2 * std::cos(0.3), 1e-14);
  EXPECT_EQ(g.distance_to_boundary(wall, {0, 0, 1}).distance, 0.0);
  // Grazing chords from the wall stay non-negative and tiny, not garbage.
  const Vec3 graze = normalize(Vec3{0, 1, -1e-9});
  const double d = g.distance_to_boundary(wall, graze).distance;
  EXPECT_GE(d, 0.0);
  EXPECT_LT(d, 1e-8);
  // Slab: only the face ahead counts; a photon on the top face moving down sees the bottom.
  const SlabGeometry slab(2.0, 1, 1);
  EXPECT_NEAR(slab.distance_to_boundary({0, 0, 0}, normalize(Vec3{1, 0, -1})).distance,
              2 * std::sqrt(2.0), 1e-14);
  EXPECT_EQ(slab.distance_to_boundary({0, 0, 0}, normalize(Vec3{1, 0, -1})).boundary,
            SlabGeometry::kBottom);
  EXPECT_TRUE(std::isinf(slab.distance_to_boundary({0, 0, -1}, {1, 0, 0}).distance));
}

TEST(TransportCylinder, BeamEntryPointsCoverTheLitSide) {
  const CylinderGeometry g(3.0, 1.0);
  const Vec3 dir = normalize(Vec3{0.5, 0.3, -0.8});
  for (double u : {0.0, 0.1, 0.5, 0.9, 0.999999}) {
    const Vec3 p = cylinder_beam_entry(g, dir, u);
    EXPECT_NEAR(std::hypot(p.y, p.z), 3.0, 1e-12);
    EXPECT_LE(dot(g.outward_normal(p, 0), dir), 1e-12);  // faces the beam
    // The impact parameter is r (2u - 1) across the projected width.
    const double s = std::hypot(dir.y, dir.z);
    EXPECT_NEAR(-p.y * dir.z / s + p.z * dir.y / s, 3.0 * (2 * u - 1), 1e-12);
  }
}

// Index-matched (n = 1 inside and out), absorbing, non-scattering cylinder under a normal beam:
// the transmitted fraction is (1/2r) int exp(-mu_a 2 sqrt(r^2 - b^2)) db, computed here by
// quadrature.
TEST(TransportCylinder, MatchedAbsorbingCylinderFollowsBeerLambertChords) {
  const double r = 10, mua = 0.05;  // um, 1/um: optical radius 0.5
  const BeamFate exact = non_scattering_cylinder(mua, r, 1.0, 1.0, {0, 0, -1});
  const CylinderBeamResult res = simulate_cylinder_beam(
      beam(medium(mua, 0, 0, 1.0), r, 1.0, {0, 0, -1}), cylinder_batch(200000, 31));
  EXPECT_EQ(res.specular.mean, 0.0);
  EXPECT_TRUE(within_sigma(res.exited, exact.exited, 3));
  EXPECT_TRUE(within_sigma(res.absorbed, exact.absorbed, 3));
  EXPECT_NEAR(exact.exited + exact.absorbed, 1.0, 1e-9);
  EXPECT_EQ(res.scatterings, 0u);
}

namespace {

// The absorbing, non-scattering cotton cylinder (r = 10, mua = 0.03, n = 1.557 in air) at normal
// and oblique incidence to the axis, in every weight mode: check(setup, its exact bounce series,
// direction, mode).
template <class Check>
void for_each_mismatched_beam(Check&& check) {
  const double r = 10, mua = 0.03, n = 1.557;
  for (const Vec3& dir : {Vec3{0, 0, -1}, normalize(Vec3{0.8, 0.3, -0.5})}) {
    const BeamFate exact = non_scattering_cylinder(mua, r, n, 1.0, dir);
    EXPECT_NEAR(exact.specular + exact.exited + exact.absorbed, 1.0, 1e-9);
    for (WeightMode mode :
         {WeightMode::implicit_capture, WeightMode::analog, WeightMode::absorption_weight}) {
      CylinderBeamSetup s = beam(medium(mua, 0, 0, n), r, 1.0, dir);
      s.options.mode = mode;
      check(s, exact, dir, mode);
    }
  }
}

}  // namespace

// The same with Fresnel boundaries (cotton n = 1.557 in air) at normal and oblique incidence to
// the axis: exercises refraction, internal reflection and the axial component.
TEST(TransportCylinder, MismatchedAbsorbingCylinderMatchesBounceSeries) {
  for_each_mismatched_beam(
      [](CylinderBeamSetup& s, const BeamFate& exact, const Vec3& dir, WeightMode) {
        const CylinderBeamResult res = simulate_cylinder_beam(s, cylinder_batch(150000, 32));
        EXPECT_TRUE(within_sigma(res.specular, exact.specular, 3)) << dir;
        EXPECT_TRUE(within_sigma(res.exited, exact.exited, 3)) << dir;
        EXPECT_TRUE(within_sigma(res.absorbed, exact.absorbed, 3)) << dir;
        EXPECT_NEAR(res.energy_imbalance, 0, 1e-12);
      });
}

// Next-event estimation of exits (TransportOptions::expected_exits) follows the same bounce
// series, in every weight mode: the exits match the exact series above, the books close, and the
// estimate is less noisy (for a non-scattering cylinder its only randomness left is the impact
// parameter and the walk's rare exits past the chain's cutoff).
TEST(TransportCylinder, ExpectedExitsMatchTheBounceSeries) {
  for_each_mismatched_beam(
      [](CylinderBeamSetup& s, const BeamFate& exact, const Vec3& dir, WeightMode mode) {
        const CylinderBeamResult plain = simulate_cylinder_beam(s, cylinder_batch(40000, 34));
        s.options.expected_exits = true;
        const CylinderBeamResult res = simulate_cylinder_beam(s, cylinder_batch(40000, 34));
        EXPECT_TRUE(within_sigma(res.exited, exact.exited, 3)) << dir;
        EXPECT_NEAR(res.energy_imbalance, 0, 1e-12);
        // Measured: 0.11-0.15 of plain; with absorption as a weight plain draws no absorption
        // either, only the internal Fresnel choices, and the ratio is 0.65.
        const double gain = mode == WeightMode::absorption_weight ? 0.8 : 0.25;
        EXPECT_LT(res.exited.std_error, gain * plain.exited.std_error) << dir;
      });
}

// No absorption: all entering energy leaves (specular + exits = 1 to rounding), for any
// scattering, with total internal reflection trapping photons for a while.
TEST(TransportCylinder, NonAbsorbingCylinderReturnsAllEnergy) {
  for (double g : {0.0, 0.8, -0.5}) {
    const CylinderBeamResult res = simulate_cylinder_beam(
        beam(medium(0, 0.2, g, 1.557), 10, 1.0, normalize(Vec3{0.4, 0.2, -0.9})),
        cylinder_batch(20000, 33));
    EXPECT_EQ(res.absorbed.mean, 0.0);
    EXPECT_EQ(res.lost.mean, 0.0);
    EXPECT_NEAR(res.specular.mean + res.exited.mean, 1.0, 1e-12);
    EXPECT_GT(res.reflections, res.photons);  // TIR did happen
  }
}

// A photon started inside a non-absorbing cylinder always gets out (launch API (b)).
TEST(TransportCylinder, InternalLaunchExits) {
  const CylinderTransport t(CylinderGeometry(5, 1.0), medium(0, 1, 0.9, 1.5));
  Rng rng(7);
  PhotonTally tally;
  struct Count {
    int exits = 0;
    double weight = 0;
    void on_exit(const ExitEvent& e) {
      ++exits;
      weight += e.weight;
      EXPECT_NEAR(std::hypot(e.position.y, e.position.z), 5.0, 1e-12);
      EXPECT_NEAR(length(e.direction), 1.0, 1e-12);
      EXPECT_GT(e.direction.y * e.position.y + e.direction.z * e.position.z, 0.0);  // leaving
    }
  } count;
  for (int i = 0; i < 2000; ++i)
    t.launch_internal({0, 1, -2}, normalize(Vec3{1, 1, 1}), 1.0, rng, count, tally);
  EXPECT_EQ(count.exits, 2000);
  EXPECT_NEAR(count.weight, 2000.0, 1e-9);
  EXPECT_NEAR(tally.imbalance(), 0, 1e-9);
  EXPECT_THROW(t.launch_internal({0, 6, 0}, {1, 0, 0}, 1.0, rng, count, tally), Error);
  EXPECT_THROW(t.launch_internal({0, 0, 0}, {1, 1, 0}, 1.0, rng, count, tally), Error);
  EXPECT_THROW(t.launch_external(0, {0, 0, 5}, {0, 0, 1}, 1.0, rng, count, tally), Error);
  EXPECT_THROW(t.launch_external(1, {0, 0, 5}, {0, 0, -1}, 1.0, rng, count, tally), Error);
}

// A photon trapped by total internal reflection in a non-interacting medium would bounce forever;
// the cap stops it and reports its weight as lost.
TEST(TransportCylinder, TrappedPhotonIsCappedAndReported) {
  TransportOptions o;
  o.max_events = 1000;
  const CylinderTransport t(CylinderGeometry(1, 1.0), medium(0, 0, 0, 1.557), o);
  Rng rng(1);
  NullRecorder none;
  PhotonTally tally;
  // From a wall-adjacent point along the tangent: every hit is at ~80 degrees, beyond critical.
  t.launch_internal({0, 0.98, 0}, {0, 0, 1}, 1.0, rng, none, tally);
  EXPECT_EQ(tally.lost, 1.0);
  EXPECT_EQ(tally.reflections, 1000u);
  EXPECT_EQ(tally.exited, 0.0);
  // Straight along the axis with nothing to interact with: lost at once, not an endless loop.
  PhotonTally axial;
  t.launch_internal({0, 0.5, 0}, {1, 0, 0}, 1.0, rng, none, axial);
  EXPECT_EQ(axial.lost, 1.0);
}

TEST(TransportCylinder, AnalogAndImplicitCaptureAgree) {
  CylinderBeamSetup s =
      beam(medium(0.01, 0.1, 0.8, 1.557), 10, 1.0, normalize(Vec3{0.3, -0.2, -0.9}));
  const CylinderBeamResult implicit = simulate_cylinder_beam(s, cylinder_batch(100000, 34));
  s.options.mode = WeightMode::analog;
  const CylinderBeamResult analog = simulate_cylinder_beam(s, cylinder_batch(100000, 35));
  EXPECT_TRUE(within_sigma(implicit.exited, analog.exited.mean, 3, analog.exited.std_error));
  EXPECT_TRUE(within_sigma(implicit.absorbed, analog.absorbed.mean, 3, analog.absorbed.std_error));
  EXPECT_NEAR(implicit.specular.mean, analog.specular.mean, 5 * implicit.specular.std_error);
}

TEST(TransportCylinder, SameBitsAtOneAndTwoThreads) {
  const CylinderBeamSetup s =
      beam(medium(0.005, 0.05, 0.8, 1.557), 10, 1.0, normalize(Vec3{0.2, 0.1, -1}));
  const CylinderBeamResult a = simulate_cylinder_beam(s, cylinder_batch(40000, 36, 1));
  const CylinderBeamResult b = simulate_cylinder_beam(s, cylinder_batch(40000, 36, 2));
  for (auto [x, y] : {std::pair{a.exited, b.exited}, std::pair{a.absorbed, b.absorbed},
                      std::pair{a.specular, b.specular}}) {
    EXPECT_EQ(std::memcmp(&x.mean, &y.mean, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&x.std_error, &y.std_error, sizeof(double)), 0);
  }
  EXPECT_EQ(a.scatterings, b.scatterings);
  EXPECT_EQ(a.reflections, b.reflections);
}

TEST(TransportCylinder, Extremes) {
  {  // optically huge: mu_t r = 1e4, albedo 0.99; roulette ends every walk
    const CylinderBeamResult res = simulate_cylinder_beam(
        beam(medium(10, 990, 0.8, 1.557), 10, 1.0, {0, 0, -1}), cylinder_batch(1000, 37));
    EXPECT_NEAR(res.energy_imbalance, 0, 1e-12);
    EXPECT_EQ(res.lost.mean, 0.0);
    EXPECT_GT(res.absorbed.mean, 0.5);
    EXPECT_TRUE(within_sigma(res.roulette, 0.0, 4));
  }
  {  // optically huge and non-absorbing: the cap bounds the runtime, its weight is reported
    CylinderBeamSetup s = beam(medium(0, 1000, 0.0, 1.557), 10, 1.0, {0, 0, -1});
    s.options.max_events = 20000;
    const CylinderBeamResult res = simulate_cylinder_beam(s, cylinder_batch(500, 38));
    EXPECT_NEAR(res.specular.mean + res.exited.mean + res.lost.mean, 1.0, 1e-12);
    EXPECT_GT(res.exited.mean, 0.5);
  }
  {  // mu_a huge: absorbed at once
    const CylinderBeamResult res = simulate_cylinder_beam(
        beam(medium(1e12, 1, 0.0, 1.557), 10, 1.0, {0, 0, -1}), cylinder_batch(2000, 39));
    EXPECT_NEAR(res.specular.mean + res.absorbed.mean, 1.0, 1e-12);
    EXPECT_LT(res.exited.mean, 1e-9);
  }
  {  // mu_s -> 0
    const CylinderBeamResult res = simulate_cylinder_beam(
        beam(medium(0, 1e-12, 0.0, 1.557), 10, 1.0, {0, 0, -1}), cylinder_batch(2000, 40));
    EXPECT_NEAR(res.specular.mean + res.exited.mean, 1.0, 1e-12);
  }
  {  // grazing: the beam 89.9 degrees from the cross-section, almost along the axis
    const double a = deg_to_rad(89.9);
    const CylinderBeamResult res = simulate_cylinder_beam(
        beam(medium(0.005, 0.05, 0.8, 1.557), 10, 1.0, {std::sin(a), 0, -std::cos(a)}),
        cylinder_batch(5000, 41));
    EXPECT_GT(res.specular.mean, 0.98);
    for (const MeanEstimate& e : {res.exited, res.absorbed})
      EXPECT_TRUE(std::isfinite(e.mean) && e.mean >= 0 && e.mean <= 1 &&
                  std::isfinite(e.std_error));
    EXPECT_NEAR(res.energy_imbalance, 0, 1e-12);
  }
}

TEST(TransportCylinder, BadInputIsRejectedWithTheFieldNamed) {
  auto message_of = [](const CylinderBeamSetup& s) {
    return weft::testing::error_of([&] { simulate_cylinder_beam(s, cylinder_batch(10, 1)); });
  };
  EXPECT_NE(message_of(beam(medium(1, 1, 0, 1.5), 0, 1, {0, 0, -1})).find("radius"),
            std::string::npos);
  EXPECT_NE(message_of(beam(medium(1, 1, 0, 1.5), 1, 1, {1, 0, 0})).find("direction"),
            std::string::npos);
  EXPECT_NE(message_of(beam(medium(1, 1, 0, 1.5), 1, 1, {0, 0, -2})).find("direction"),
            std::string::npos);
  EXPECT_NE(message_of(beam(medium(1, -1, 0, 1.5), 1, 1, {0, 0, -1})).find("mu_s"),
            std::string::npos);
  EXPECT_NE(message_of(beam(medium(1, 1, 0, 1.5), 1, std::nan(""), {0, 0, -1})).find("n_outside"),
            std::string::npos);
}
