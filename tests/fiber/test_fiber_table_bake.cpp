// The fiber baker end to end: Mie medium -> cylinder transport -> table. Energy books, the white
// furnace, the agreement of the direct and the paper's BSSRDF route, the fiber's symmetries,
// reproducibility, extremes and table sampling. Definitions: docs/fiber-bsdf.md.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <thread>
#include <vector>

#include "chi2.h"
#include "fiber_bake_test_util.h"
#include "transport_test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/sphere_mapping.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/fiber_bake_request.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/registry.h"
#include "weft/materials/tabulated_bsdf.h"

using namespace weft;

using namespace weft::testing;

// With plain exits (the bake before next-event estimation) and with the defaults (next-event
// estimation, whose table is scaled to the walks' own exits): both tables hold exactly the energy
// the walks sent out, 1 plus the surface lobe's sampling excess, at only 1 500 photons per band.
// Unscaled, a next-event table's energy scatters about it as 1/sqrt(N): at these photons by up to
// about 0.02 (the recorded exit_fraction, checked to differ).
TEST(FiberTableBake, WhiteCottonIsLosslessAndPassesTheWhiteFurnace) {
  for (const FiberExitEstimator estimator :
       {FiberExitEstimator::kPlain, FiberTableBakeOptions{}.estimator}) {
    SCOPED_TRACE(fiber_exit_estimator_name(estimator));
    // No dye, non-absorbing inclusions: everything that hits the fiber leaves it.
    FiberTableBakeOptions o{.resolution = 4, .photons_per_band = 1500, .threads = 2, .passes = 2};
    o.estimator = estimator;
    const auto r = bake_fiber_table(load_fiber_spec("white-cotton"), o);
    ASSERT_FALSE(r.cancelled);
    ASSERT_EQ(r.bands.size(), static_cast<size_t>(kNumBands));
    double excess_sum = 0, largest_exit_excess = 0;
    for (const auto& b : r.bands) {
      EXPECT_EQ(b.photons, o.photons_per_band);
      EXPECT_EQ(b.absorbed_fraction, 0.0);
      EXPECT_EQ(b.lost_fraction, 0.0);
      EXPECT_EQ(b.roulette_net, 0.0);
      // The books balance per photon; the only differences from 1 are the mean-zero excesses of
      // the sampled surface weight over the tabulated surface albedo and of the next-event
      // estimated exits over the walks' own (zero with plain exits).
      EXPECT_NEAR(b.energy_balance, 1.0, 1e-12);
      EXPECT_NEAR(b.walk_exit_fraction() - b.surface_sampling_excess, 1.0, 1e-12);
      // The table holds exactly the walks' exiting energy (sum of f D_i D_o = pi * exit).
      EXPECT_NEAR(b.energy_table, b.walk_exit_fraction(), 1e-12);
      EXPECT_NEAR(b.energy_scale * b.exit_fraction, b.walk_exit_fraction(), 1e-12);
      if (estimator == FiberExitEstimator::kPlain) {
        EXPECT_EQ(b.energy_scale, 1.0);
      }
      excess_sum += b.surface_sampling_excess;
      largest_exit_excess = std::max(largest_exit_excess, std::abs(b.expected_exit_excess));
    }
    // Next-event estimation's tallied exits do differ from the walks' (else the scaling tests
    // nothing): by more than 0.001 in some band.
    if (estimator == FiberExitEstimator::kNextEvent) {
      EXPECT_GT(largest_exit_excess, 1e-3);
    }
    // The excess is an average of (w_s - albedo) over 49500 photons, |w_s - albedo| <= 1, so its
    // mean is 0 within 5 / sqrt(49500) = 0.022 even in the worst case of unit spread.
    EXPECT_LT(std::abs(excess_sum / kNumBands), 0.022);
    // The stored float table keeps the furnace to float rounding.
    const auto d = DirectionGrid{o.resolution}.cosine_weighted_areas();
    const int cells = DirectionGrid{o.resolution}.bins();
    for (int band : {0, 16, 32}) {
      double e = 0;
      for (int i = 0; i < cells; ++i)
        for (int k = 0; k < cells; ++k) e += r.table.at(i, k, band) * d[i] * d[k];
      EXPECT_NEAR(e / kPi, r.bands[band].walk_exit_fraction(), 1e-5) << band;
    }
  }
}

TEST(FiberTableBake, RedCottonBooksBalanceAndAbsorbsInTheGreen) {
  FiberTableBakeOptions o;
  o.resolution = 4;
  o.photons_per_band = 1000;
  o.passes = 1;
  const auto r = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  for (const auto& b : r.bands) {
    EXPECT_NEAR(b.energy_balance, 1.0, 1e-12) << b.wavelength_nm;
    EXPECT_GE(b.absorbed_fraction, 0.0);
    EXPECT_GE(b.exit_fraction, 0.0);
    EXPECT_LE(b.exit_fraction, 1.1);
  }
  // The dye (docs/presets.md) absorbs around 520-530 nm and hardly at 700 nm.
  EXPECT_GT(r.bands[14].absorbed_fraction, 3 * r.bands[31].absorbed_fraction);
}

// Congo red's measured spectrum (fiber/data/dyes/congo-red.json) is more saturated than sRGB:
// the RGB reduction of the red cotton's table has negative values, which are set to 0, so its
// summary warns and names --bands spectral; the spectral table of the same spec keeps every band
// and has nothing to warn of. The undyed white cotton's RGB table is inside the gamut.
TEST(FiberTableBake, RgbTableOfASaturatedDyeWarnsThatItLeftTheGamut) {
  FiberTableBakeOptions o;
  o.resolution = 4;
  o.photons_per_band = 1000;
  o.passes = 1;
  o.spectral = false;
  const FiberSpec red = load_fiber_spec("red-cotton");
  const auto rgb = bake_fiber_table(red, o);
  EXPECT_GT(rgb.rgb_negative_clipped, 0.0);
  const nlohmann::json warned = fiber_bake_summary(rgb, red, o, "red.exr", 0)["warnings"];
  ASSERT_FALSE(warned.empty());
  EXPECT_NE(warned[0].get<std::string>().find("outside the sRGB gamut"), std::string::npos);
  EXPECT_NE(warned[0].get<std::string>().find("--bands spectral"), std::string::npos);
  o.spectral = true;
  EXPECT_TRUE(
      fiber_bake_summary(bake_fiber_table(red, o), red, o, "red.exr", 0)["warnings"].empty());
  o.spectral = false;
  const FiberSpec white = load_fiber_spec("white-cotton");
  EXPECT_TRUE(
      fiber_bake_summary(bake_fiber_table(white, o), white, o, "white.exr", 0)["warnings"].empty());
}

TEST(FiberTableBake, DirectAndBssrdfRoutesAgreeWithinStatisticalError) {
  // One band of a scattering, absorbing fiber (mu_s R ~ 5), R = 3 (18 x 18 cells), the paper's
  // route at its default grid (64 x 64 incident bins, 180 offsets around the axis).
  const FiberSpec spec = test_spec(20, 0.10, 0.01);
  const MediumBand mb = compute_medium_band(spec, 16);
  const FiberBandPhysics ph = fiber_band_physics(spec, mb);
  const auto [direct, bssrdf] = bake_both_routes(ph);
  // 324 cells; at 4.5 standard errors a false alarm has probability 324 * 7e-6 = 0.002, but the
  // standard errors themselves come from 5 bakes (t with 8 dof): allow one outlier cell.
  EXPECT_LE(count_outliers(direct.mean, direct.se, bssrdf.mean, bssrdf.se, 4.5), 1);
  // And the two agree on the total to the BSSRDF route's stated quadrature error (2e-3).
  double a = 0, b = 0;
  const DirectionGrid g{3};
  const auto d = g.cosine_weighted_areas();
  const int cells = g.bins();
  for (int i = 0; i < cells; ++i)
    for (int o = 0; o < cells; ++o)
      a += direct.mean[i * cells + o] * d[i] * d[o], b += bssrdf.mean[i * cells + o] * d[i] * d[o];
  EXPECT_NEAR(a, b, 2e-3 * a + 0.01 * a);
}

// The analytic surface lobe (cells by quadrature, the lobe named in the table) against the
// sampled one (the photons' draws binned): the same f in expectation. On the polyester filament
// (GGX alpha 0.1, the lobe narrower than the bins), R 4: the analytic table differs from a sampled
// one of another seed by no more than two sampled tables differ (its lobe carries no noise), the
// total albedo agrees to the photons' noise, and without its lobe the table is what the photons
// sent through the volume alone.
TEST(FiberTableBake, AnalyticSurfaceLobeHoldsTheSampledTablesF) {
  const FiberSpec spec = load_fiber_spec("polyester-filament");
  FiberTableBakeOptions o;
  o.resolution = 4;
  o.photons_per_band = 4000;
  o.spectral = false;
  o.threads = 2;
  const auto bake = [&](FiberSurfaceLobe lobe, uint64_t seed) {
    FiberTableBakeOptions v = o;
    v.surface_lobe = lobe, v.seed = seed;
    return bake_fiber_table(spec, v);
  };
  const auto s1 = bake(FiberSurfaceLobe::kSampled, 1), s2 = bake(FiberSurfaceLobe::kSampled, 2);
  const auto a1 = bake(FiberSurfaceLobe::kAnalytic, 1);
  ASSERT_FALSE(s1.table.surface_lobe);
  ASSERT_TRUE(a1.table.surface_lobe);
  EXPECT_EQ(a1.table.surface_lobe->distribution.alpha, 0.1);
  EXPECT_EQ(a1.table.surface_lobe->ior, std::vector<double>(3, 1.6));
  const DirectionGrid g{4};
  const auto d = g.cosine_weighted_areas();
  const auto rms = [&](const TabulatedBsdfTable& x, const TabulatedBsdfTable& y) {
    double num = 0, den = 0;
    for (int i = 0; i < g.bins(); ++i)
      for (int j = 0; j < g.bins(); ++j)
        for (int c = 0; c < 3; ++c) {
          const double w = d[i] * d[j], a = x.at(i, j, c), b = y.at(i, j, c);
          num += w * (a - b) * (a - b), den += w * b * b;
        }
    return std::sqrt(num / den);
  };
  const double noise2 = rms(s1.table, s2.table), analytic = rms(a1.table, s2.table);
  std::printf("sampled vs sampled %.4f, analytic vs sampled %.4f\n", noise2, analytic);
  EXPECT_LT(analytic, noise2);
  const auto ta = a1.table.total_albedo(), ts = s2.table.total_albedo();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(ta[c], ts[c], 0.01 * ts[c]) << c;
  // Taken out again, the lobe leaves the volume's light: its total is the photons' exits less the
  // surface's (the summary's per-band figures, about 0.09 of the light on this fiber).
  const auto rest = a1.table.without_surface_lobe("").total_albedo();
  const double surface = a1.bands[16].surface_fraction;
  EXPECT_GT(surface, 0.05);
  EXPECT_NEAR(rest[1], ta[1] - surface, 0.02 * ta[1]);
}

TEST(FiberTableBake, TableHasTheFibersMirrorSymmetries) {
  const FiberSpec spec = test_spec(8, 0.03, 0.005);
  const MediumBand mb = compute_medium_band(spec, 20);
  const FiberBandPhysics ph = fiber_band_physics(spec, mb);
  FiberBakeSettings s = weft::testing::bake_settings(3, 60000, 2);
  const CellStats st = cell_stats(6, [&](uint64_t seed) {
    s.seed = seed;
    return bake_fiber_band_direct(ph, s, nullptr);
  });
  const DirectionGrid g{3};
  const int cells = g.bins();
  for (bool flip_x : {true, false}) {
    std::vector<double> m(st.mean.size()), se(st.se.size());
    const int axis = flip_x ? 0 : 1;
    for (int i = 0; i < cells; ++i)
      for (int o = 0; o < cells; ++o) {
        const size_t src =
            static_cast<size_t>(g.mirrored_bin(i, axis)) * cells + g.mirrored_bin(o, axis);
        m[i * cells + o] = st.mean[src];
        se[i * cells + o] = st.se[src];
      }
    EXPECT_LE(count_outliers(st.mean, st.se, m, se, 4.5), 2)
        << (flip_x ? "axis flip" : "binormal flip");
  }
}

namespace {

// The fiber's scattering per unit length F(w_i, w_o) is reciprocal (the BSSRDF is, Fig. 1 of the
// paper with both media outside equal), while the point BSDF f is not (docs/fiber-bsdf.md).
// Binned by the axial cosines s_i, s_o and the azimuth difference, reciprocity reads
// H[a][b][c] = H[b][a][n - 1 - c]. Over 6 independent bakes of 'photons': the number of bins
// where the two differ by more than 4.5 standard errors, and the largest over the smallest bin.
struct ReciprocityCheck {
  int outliers = 0;
  double spread = 0;
};
ReciprocityCheck far_field_reciprocity(const FiberBandPhysics& ph, uint64_t photons) {
  FiberBakeSettings s = weft::testing::bake_settings(2, photons, 2);
  s.far_field_s_bins = 4;
  s.far_field_psi_bins = 5;
  const int k = 6, ns = 4, np = 5;
  std::vector<double> sum, sum2;
  for (int rep = 0; rep < k; ++rep) {
    s.seed = 500 + rep;
    const auto t = bake_fiber_band_direct(ph, s, nullptr);
    EXPECT_EQ(t.far_field.size(), static_cast<size_t>(ns * ns * np));
    if (sum.empty()) sum.assign(t.far_field.size(), 0), sum2.assign(t.far_field.size(), 0);
    for (size_t c = 0; c < t.far_field.size() && c < sum.size(); ++c)
      sum[c] += t.far_field[c], sum2[c] += t.far_field[c] * t.far_field[c];
  }
  std::vector<double> mean(sum.size()), se(sum.size());
  for (size_t c = 0; c < sum.size(); ++c) {
    mean[c] = sum[c] / k;
    se[c] = std::sqrt(std::max(0.0, sum2[c] / k - mean[c] * mean[c]) / (k - 1));
  }
  std::vector<double> swapped(sum.size()), swapped_se(sum.size());
  for (int a = 0; a < ns; ++a)
    for (int b = 0; b < ns; ++b)
      for (int c = 0; c < np; ++c) {
        const size_t src = (static_cast<size_t>(b) * ns + a) * np + (np - 1 - c);
        swapped[(static_cast<size_t>(a) * ns + b) * np + c] = mean[src];
        swapped_se[(static_cast<size_t>(a) * ns + b) * np + c] = se[src];
      }
  ReciprocityCheck r;
  r.outliers = count_outliers(mean, se, swapped, swapped_se, 4.5);
  double lo = 1e300, hi = 0;
  for (double v : mean) lo = std::min(lo, v), hi = std::max(hi, v);
  r.spread = lo > 0 ? hi / lo : 1e300;
  return r;
}

FiberSpec rough_dielectric(FiberSpec spec) {
  spec.boundary = FiberBoundary::kRoughDielectric;
  return spec;
}

}  // namespace

TEST(FiberTableBake, FiberScatteringIsReciprocal) {
  const FiberSpec spec = test_spec(6, 0.04, 0.003);
  const MediumBand mb = compute_medium_band(spec, 10);
  const ReciprocityCheck r = far_field_reciprocity(fiber_band_physics(spec, mb), 50000);
  // 80 bins (40 distinct pairs): allow one 4.5-sigma outlier, as the errors come from 6 bakes.
  EXPECT_LE(r.outliers, 1);
  // The tally is not trivially symmetric: light mostly goes forward (s_o near s_i), so the
  // bins differ a lot from each other.
  EXPECT_GT(r.spread, 5);
}

TEST(FiberTableBake, RoughDielectricBoundaryIsReciprocal) {
  // The same check with the rough dielectric boundary both ways (rough_dielectric.h), at the
  // spec's roughness and at a rough 0.8 where light often scatters more than once on the
  // microsurface.
  for (const double alpha : {0.3, 0.8}) {
    FiberSpec spec = rough_dielectric(test_spec(6, 0.04, 0.003));
    spec.roughness_alpha = alpha;
    const MediumBand mb = compute_medium_band(spec, 10);
    const FiberBandPhysics ph = fiber_band_physics(spec, mb);
    ASSERT_TRUE(ph.boundary);
    const ReciprocityCheck r = far_field_reciprocity(ph, 50000);
    EXPECT_LE(r.outliers, 1) << "alpha " << alpha;
    EXPECT_GT(r.spread, 5) << "alpha " << alpha;
  }
}

TEST(FiberTableBake, RoughDielectricBoundaryConservesEnergy) {
  // A lossless fiber (no dye, non-absorbing voids; and a clear one without particles, where
  // light bounces between the rough walls) returns all light: the microsurface walk keeps the
  // energy that single-scattering microfacet models lose (reported by single_scatter_albedo).
  for (const double alpha : {0.3, 0.8})
    for (const double voids : {0.0, 0.02}) {
      FiberSpec spec = rough_dielectric(test_spec(8, voids, 0.0));
      spec.roughness_alpha = alpha;
      const FiberBandPhysics ph = fiber_band_physics(spec, compute_medium_band(spec, 16));
      FiberBakeSettings s = weft::testing::bake_settings(3, 20000, 2);
      const auto t = bake_fiber_band_direct(ph, s, nullptr);
      const std::string where =
          "alpha " + std::to_string(alpha) + " voids " + std::to_string(voids);
      EXPECT_NEAR(t.exit_fraction, 1.0, 1e-12) << where;
      EXPECT_EQ(t.absorbed_fraction, 0.0) << where;
      EXPECT_EQ(t.lost_fraction, 0.0) << where;
      EXPECT_EQ(t.surface_sampling_excess, 0.0) << where;
      EXPECT_NEAR(t.energy_balance(), 1.0, 1e-12) << where;
      EXPECT_NEAR(fiber_table_energy(t) / kPi, 1.0, 1e-12) << where;
      // Both parts are there: light reflected by the interface and light through the volume.
      EXPECT_GT(t.surface_fraction, 0.02) << where;
      EXPECT_LT(t.surface_fraction, 0.5) << where;
    }
  // At alpha 0.8 a single-scattering model would lose a measurable share at grazing incidence
  // (what the walk keeps): the quadrature of its first step.
  const RoughDielectricInterface rd(MicrofacetModel::kGgx, 0.8, 1.0, 1.557);
  const RoughDielectricAlbedo a = rd.single_scatter_albedo(Vec3{safe_sqrt(1 - 0.01), 0, 0.1});
  EXPECT_LT(a.reflected + a.transmitted, 0.99);
}

TEST(FiberTableBake, RoughDielectricBoundaryTendsToTheSmoothOneAsAlphaVanishes) {
  // alpha -> 0: the rough interface is the smooth dielectric boundary both ways (Fresnel at
  // entry and exit, smooth_fiber_physics). Every cell of the table within noise (5 bakes each).
  FiberSpec spec = rough_dielectric(test_spec(8, 0.03, 0.005));
  spec.roughness_alpha = 1e-4;
  const MediumBand mb = compute_medium_band(spec, 20);
  const FiberBandPhysics rough = fiber_band_physics(spec, mb);
  const FiberBandPhysics smooth =
      smooth_fiber_physics(TransportMedium{mb.mu_a_per_um, mb.mu_s_per_um, mb.host_n, mb.phase},
                           spec.fiber_radius_um, 1.0);
  FiberBakeSettings s = weft::testing::bake_settings(3, 30000, 2);
  const int k = 5;
  double surface_rough = 0, surface_smooth = 0;
  const CellStats a = cell_stats(k, [&](uint64_t seed) {
    s.seed = seed;
    const auto t = bake_fiber_band_direct(rough, s, nullptr);
    surface_rough += t.surface_fraction / k;
    return t;
  });
  const CellStats b = cell_stats(k, [&](uint64_t seed) {
    s.seed = seed + 50;
    const auto t = bake_fiber_band_direct(smooth, s, nullptr);
    surface_smooth += t.surface_fraction / k;
    return t;
  });
  // 324 cells at 4.5 standard errors from 5 bakes each: allow one outlier (as the route test).
  EXPECT_LE(count_outliers(a.mean, a.se, b.mean, b.se, 4.5), 1);
  // The surface share (smooth: the Fresnel reflectance averaged over the fiber, about 0.08 at
  // n = 1.557) within the rough one's binomial noise over 150 000 photons.
  EXPECT_NEAR(surface_rough, surface_smooth, 4.5 * std::sqrt(0.1 * 0.9 / (k * 30000.0)));
  EXPECT_GT(surface_smooth, 0.05);
}

TEST(FiberTableBake, BitIdenticalAtOneAndTwoThreads) {
  FiberTableBakeOptions o{.resolution = 4, .photons_per_band = 300, .threads = 1, .passes = 2};
  const auto a = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  o.threads = 2;
  const auto b = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  ASSERT_EQ(a.table.values.size(), b.table.values.size());
  EXPECT_EQ(a.table.checksum(), b.table.checksum());
  for (size_t i = 0; i < a.table.values.size(); ++i)
    ASSERT_EQ(a.table.values[i], b.table.values[i]);
}

// The bands of a pass run side by side, one thread each (trace_fiber_bands): the caller's
// progress callback is still called for the photons on the calling thread alone (a front end's
// need not be thread-safe), and a stop it returns mid-bake keeps the passes every band finished:
// resumed from the last checkpoint, the bake ends with the sums of one that was never stopped,
// bit for bit.
TEST(FiberTableBake, BandsSideBySideReportOnTheCallingThreadAndResumeToTheSameBits) {
  const FiberSpec spec = load_fiber_spec("red-cotton");
  const FiberTableBakeOptions o{
      .resolution = 4, .photons_per_band = 600, .threads = 2, .passes = 3};
  const auto caller = std::this_thread::get_id();
  int calls = 0, calls_elsewhere = 0;
  const FiberBandsResult whole = trace_fiber_bands(spec, o, {}, [&](const ProgressUpdate& u) {
    if (u.stage != "photons") return true;  // the medium's stage reports from its own threads
    ++calls;
    if (std::this_thread::get_id() != caller) ++calls_elsewhere;
    return true;
  });
  ASSERT_FALSE(whole.cancelled);
  EXPECT_GT(calls, 0);
  EXPECT_EQ(calls_elsewhere, 0);
  // Stopped once half the photons are reported; each finished pass checkpointed.
  FiberBandWork work;
  std::vector<FiberBandState> checkpoint;
  work.on_pass = [&](const std::vector<FiberBandState>& states) { checkpoint = states; };
  const uint64_t total = o.photons_per_band * kNumBands;
  const FiberBandsResult stopped = trace_fiber_bands(spec, o, work, [&](const ProgressUpdate& u) {
    return !(u.stage == "photons" && u.done >= total / 2);
  });
  ASSERT_TRUE(stopped.cancelled);
  ASSERT_EQ(checkpoint.size(), static_cast<size_t>(kNumBands));  // the first pass: a third
  for (const FiberBandState& b : checkpoint) EXPECT_LT(b.passes_done, o.passes);
  work.start = checkpoint;
  work.on_pass = nullptr;
  const FiberBandsResult resumed = trace_fiber_bands(spec, o, work);
  ASSERT_FALSE(resumed.cancelled);
  for (int b = 0; b < kNumBands; ++b) {
    EXPECT_EQ(resumed.bands[b].photons, whole.bands[b].photons) << b;
    EXPECT_EQ(resumed.bands[b].passes_done, o.passes) << b;
    EXPECT_TRUE(resumed.bands[b].weighted_sum == whole.bands[b].weighted_sum) << b;
    EXPECT_EQ(resumed.bands[b].exit, whole.bands[b].exit) << b;
  }
}

TEST(FiberTableBake, RoughDielectricBoundaryIsBitIdenticalAtOneAndTwoThreads) {
  const FiberSpec spec = rough_dielectric(load_fiber_spec("red-cotton"));
  // The rough boundary's defaults: plain exits and one walk per photon (fiber_bake_defaults).
  FiberTableBakeOptions o = fiber_bake_defaults(spec);
  EXPECT_EQ(o.estimator, FiberExitEstimator::kPlain);
  EXPECT_EQ(o.surface_samples, 1);
  o.resolution = 4, o.photons_per_band = 200, o.threads = 1, o.passes = 2;
  const auto a = bake_fiber_table(spec, o);
  o.threads = 2;
  const auto b = bake_fiber_table(spec, o);
  EXPECT_EQ(a.table.checksum(), b.table.checksum());
  EXPECT_EQ(a.table.metadata.at("boundary"), "rough-dielectric");
  // The default's header has no boundary entry (its tables are those of before the option).
  o = FiberTableBakeOptions{.resolution = 4, .photons_per_band = 20, .threads = 2};
  EXPECT_EQ(bake_fiber_table(load_fiber_spec("red-cotton"), o).table.metadata.count("boundary"),
            0u);
  // A bake of the BSSRDF route likewise drops what is the direct route's.
  o = fiber_bake_defaults(load_fiber_spec("red-cotton"), FiberBakeRoute::kBssrdf);
  EXPECT_EQ(o.estimator, FiberExitEstimator::kPlain);
  EXPECT_EQ(o.entry, FiberEntrySampling::kRandom);
  EXPECT_EQ(o.surface_samples, FiberTableBakeOptions{}.surface_samples);
}

TEST(FiberTableBake, ExtremesStayFiniteAndBalanced) {
  struct Case {
    const char* name;
    FiberSpec spec;
    uint64_t max_events;
  };
  const std::vector<Case> cases = {
      {"no particles (mu_s = 0)", test_spec(8, 0.0, 0.0), 10'000'000},
      {"total absorption (dye 1e4 / um)", test_spec(8, 0.02, 1e4), 10'000'000},
      {"optically huge fiber (R = 2e4 um, mu_t R ~ 1e3)", extreme_spec(2e4, 0.02, 0.0), 20'000},
      {"tiny fiber (R = 0.05 um)", extreme_spec(0.05, 0.02, 0.0), 10'000'000},
      {"tiny particles (r = 1e-4 um, x ~ 1e-3)", test_spec(8, 0.05, 0.0, 1e-4), 10'000'000},
      {"large particles (r = 50 um, x ~ 1e3)", extreme_spec(400, 0.05, 0.0, 50), 10'000'000},
  };
  for (const auto& c : cases) {
    const MediumBand mb = compute_medium_band(c.spec, 16);
    const FiberBandPhysics ph = fiber_band_physics(c.spec, mb, c.max_events);
    FiberBakeSettings s;
    s.resolution = 4;
    s.photons = 400;
    const auto t = bake_fiber_band_direct(ph, s, nullptr);
    EXPECT_NEAR(t.energy_balance(), 1.0, 1e-9) << c.name;
    for (double v : t.f) ASSERT_TRUE(std::isfinite(v) && v >= 0) << c.name;
    EXPECT_GE(t.lost_fraction, 0.0) << c.name;
    if (std::string(c.name).rfind("total absorption", 0) == 0) {
      // Nothing comes back out of the volume: only the surface lobe leaves.
      EXPECT_NEAR(t.exit_fraction, t.surface_fraction, 1e-6) << c.name;
    }
    if (std::string(c.name).rfind("no particles", 0) == 0) {
      EXPECT_EQ(t.scattering_events, 0u);
      EXPECT_EQ(t.absorbed_fraction, 0.0);
    }
  }
}

TEST(FiberTableBake, BakedTableSamplingPassesChiSquare) {
  // The renderer samples the baked table per view bin; chi^2 of sample() against pdf() for a
  // red-cotton table at a steep, an oblique and a grazing view. (Views are above B's horizon:
  // light leaves B outwards, and the table is 0 for views below it; light from behind B is what
  // sample() draws as wi.)
  FiberTableBakeOptions o;
  o.resolution = 8;
  o.photons_per_band = 3000;
  o.passes = 1;
  o.spectral = false;
  const auto r = bake_fiber_table(load_fiber_spec("red-cotton"), o);
  const Bsdf bsdf = TabulatedBsdf{TabulatedBsdfData::prepare(r.table)};
  const weft::testing::DirectionGridBins grid{8, 4};  // the table's own cells
  const double significance = weft::testing::sidak_significance(0.01, 3);
  for (const Vec3& wo : {normalize(Vec3{0.2, 0.3, 0.9}), normalize(Vec3{0.6, -0.5, 0.3}),
                         normalize(Vec3{0.1, 0.99, 0.05})}) {
    const auto res =
        weft::testing::chi2_test(weft::testing::bsdf_sampler(bsdf, wo),
                                 weft::testing::bsdf_pdf(bsdf, wo), grid, 200000, significance, 77);
    EXPECT_TRUE(res.passed) << res.message;
  }
}

// Absorption as a weight (transport.h) estimates the same table as implicit capture: one band of a
// scattering, absorbing fiber (mu_s R ~ 5, as in the route test above), R = 3, 5 seeds each, with
// the same outlier allowance as there, and the same energy books to 4.5 standard errors.
// Next-event estimation of exits, surface samples and mirror folding (docs/fiber-bsdf.md, "Fewer
// photons for the same noise") estimate the plain bake's table. One band of the scattering,
// absorbing fiber of the route test (mu_s R ~ 5), R = 3 (324 cell pairs), 8 bakes of 40 000
// photons each per estimator: plain; next-event; next-event with 4 surface samples, folded.
// Per cell, the difference from plain over its standard error has an RMS near 1: with standard
// errors from 8 bakes each (Welch: 7 to 14 degrees of freedom) its square has mean 1.2 to 1.4,
// so the RMS lies near 1.1-1.2, and a bias of one standard error in every cell would lift it to
// 1.5. No cell lies beyond 4.5 standard errors but the one the route test allows. The exit and
// absorbed fractions agree within 4.5 standard errors, the books close per photon, the table
// holds what was recorded, and the noise is lower.
// Stratified entries (FiberEntrySampling::kStratified: per task the points of a randomised Sobol'
// sequence, core/sobol.h) estimate the same table as independent ones: the normalised differences
// of the cells against plain random entries, by the criteria of the test above (8 bakes each, at
// most one cell beyond 4.5 standard errors, their RMS in [0.8, 1.4]; a bias of one standard error
// in every cell lifts it to 1.5), for the plain estimator and for next-event estimation with four
// surface samples (whose lobe uniforms are Sobol' dimensions too); the exit and absorbed
// fractions agree within 4.5 standard errors and the books close per photon.
// At a fixed seed, absorption as a weight keeps every photon's path when the dye changes, so each
// photon's exit weight is w exp(-mu_a L) for its own path length L: the bake's albedo is then
// exactly decreasing and convex in the dye (mu_a is linear in it), band by band, to rounding. The
// default (implicit capture with roulette) draws its free paths from mu_a + mu_s, so the same steps
// move every path and the albedo jitters by its noise: not monotone (the inner objective of
// weft verify --fit was as rough, docs/verify.md). Red-cotton, RGB, R = 4, 2000 photons per band,
// dye 1.00, 1.01, ..., 1.04.
TEST(FiberTableBake, RejectsBadOptions) {
  FiberTableBakeOptions o;
  o.resolution = 1;
  EXPECT_THROW(bake_fiber_table(load_fiber_spec("white-cotton"), o), Error);
  o.resolution = 4;
  o.photons_per_band = 0;
  EXPECT_THROW(bake_fiber_table(load_fiber_spec("white-cotton"), o), Error);
  o.photons_per_band = 10;
  o.weight_mode = WeightMode::analog;  // the fiber bakers keep weights; analog is the slab's
  EXPECT_THROW(bake_fiber_table(load_fiber_spec("white-cotton"), o), Error);
  o.weight_mode = WeightMode::implicit_capture;
  // Next-event estimation needs the direct route and the smooth boundary's analytic transmittance.
  o.estimator = FiberExitEstimator::kNextEvent;
  o.route = FiberBakeRoute::kBssrdf;
  EXPECT_NE(weft::testing::error_of([&] {
              bake_fiber_table(load_fiber_spec("white-cotton"), o);
            }).find("estimator"),
            std::string::npos);
  o.route = FiberBakeRoute::kDirect;
  EXPECT_NE(weft::testing::error_of([&] {
              bake_fiber_table(rough_dielectric(load_fiber_spec("white-cotton")), o);
            }).find("expected_exits"),
            std::string::npos);
  EXPECT_THROW(parse_fiber_exit_estimator("mis", "estimator"), Error);
  // The analytic surface lobe is the smooth boundary's Cook-Torrance lobe, on the direct route.
  o.estimator = FiberExitEstimator::kPlain;
  o.surface_lobe = FiberSurfaceLobe::kAnalytic;
  EXPECT_NE(weft::testing::error_of([&] {
              bake_fiber_table(rough_dielectric(load_fiber_spec("white-cotton")), o);
            }).find("smooth boundary"),
            std::string::npos);
  o.route = FiberBakeRoute::kBssrdf;
  EXPECT_NE(weft::testing::error_of([&] {
              bake_fiber_table(load_fiber_spec("white-cotton"), o);
            }).find("direct route"),
            std::string::npos);
}

// Every option that changes a bake's table changes its cache entry's name, and the defaults keep
// the names entries had before the key grew (so existing caches stay valid).
TEST(FiberTableBake, CacheKeyHoldsEveryOptionThatChangesTheTable) {
  const std::filesystem::path dir = "cache";
  const FiberSpec spec = load_fiber_spec("white-cotton");
  const FiberTableBakeOptions base;
  const auto name = [&](const FiberTableBakeOptions& o) {
    return fiber_table_cache_file(dir, spec, o).filename().string();
  };
  std::vector<FiberTableBakeOptions> variants(13, base);
  variants[0].resolution = 6;
  variants[1].photons_per_band = 1000;
  variants[2].seed = 2;
  variants[3].passes = 4;
  variants[4].spectral = false;
  variants[5].weight_mode = WeightMode::absorption_weight;
  variants[6].route = FiberBakeRoute::kBssrdf;
  variants[7].max_events_per_photon = 1000;
  // The estimator options, each turned away from the default (whichever it is).
  variants[8].estimator = base.estimator == FiberExitEstimator::kPlain
                              ? FiberExitEstimator::kNextEvent
                              : FiberExitEstimator::kPlain;
  variants[9].mirror_fold = !base.mirror_fold;
  variants[10].surface_samples = base.surface_samples == 4 ? 2 : 4;
  variants[11].entry = base.entry == FiberEntrySampling::kRandom ? FiberEntrySampling::kStratified
                                                                 : FiberEntrySampling::kRandom;
  variants[12].surface_lobe = FiberSurfaceLobe::kAnalytic;
  std::set<std::string> names{name(base)};
  for (const auto& v : variants) EXPECT_TRUE(names.insert(name(v)).second) << name(v);
  // Threads change nothing (a bake's bits do not depend on them).
  FiberTableBakeOptions threads = base;
  threads.threads = 7;
  EXPECT_EQ(name(threads), name(base));
}

// The bake cache never serves a table baked with one set of estimator options for another: an
// entry of the former default (plain exits, no folding, one surface sample, random entries) is not
// read for today's default, nor the reverse, and the former default's entry keeps the name it had
// before these options existed (so caches written then stay valid for bakes that ask for it).
TEST(FiberTableBake, CacheKeepsTheFormerDefaultsTablesApart) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "weft-bake-cache-defaults";
  fs::remove_all(dir);
  const FiberSpec spec = load_fiber_spec("white-cotton");
  FiberTableBakeOptions now{.resolution = 2, .photons_per_band = 64, .threads = 2};
  now.spectral = false;
  FiberTableBakeOptions former = now;
  former.estimator = FiberExitEstimator::kPlain;
  former.mirror_fold = false;
  former.surface_samples = 1;
  former.entry = FiberEntrySampling::kRandom;
  // The name this entry had before the defaults changed (printed by this test at commit 886028c,
  // whose key named none of these options at their former defaults).
  EXPECT_EQ(fiber_table_cache_file(dir, spec, former).filename().string(),
            "fiber-a8281024d6a0e84e-3914f0fcf59896a4.exr");
  bool baked = false;
  const fs::path a = cached_fiber_table(dir, spec, former, no_progress(), &baked);
  EXPECT_TRUE(baked);
  const fs::path b = cached_fiber_table(dir, spec, now, no_progress(), &baked);
  EXPECT_TRUE(baked) << "the former default's entry was served for the new default";
  EXPECT_NE(a, b);
  EXPECT_EQ(cached_fiber_table(dir, spec, former, no_progress(), &baked), a);
  EXPECT_FALSE(baked);
  EXPECT_EQ(cached_fiber_table(dir, spec, now, no_progress(), &baked), b);
  EXPECT_FALSE(baked);
  // What each entry holds says how it was baked.
  EXPECT_EQ(TabulatedBsdfTable::read_exr(a).metadata.count("mirror_fold"), 0u);
  EXPECT_EQ(TabulatedBsdfTable::read_exr(b).metadata.count("mirror_fold"),
            now.mirror_fold ? 1u : 0u);
  fs::remove_all(dir);
}

TEST(FiberTableBake, FiberTableMaterialBakesASpecOnDemandOnce) {
  // "model only what a scene requires": a fiber_table named by its spec is baked on first use,
  // kept in the cache under a content key, and read back (not re-baked) afterwards.
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "weft-bake-on-demand";
  fs::remove_all(dir);
  fs::create_directories(dir);
  MaterialContext ctx;
  ctx.base_dir = dir;
  ctx.source_file = "scene.json";
  ctx.field_prefix = "materials.seat.params";
  ctx.fiber_tables = fiber_table_resolver();
  int progress_calls = 0;
  ctx.progress = [&](const ProgressUpdate&) { return ++progress_calls > 0; };
  const nlohmann::json params = {{"spec", "white-cotton"}, {"resolution", 4}, {"photons", 200}};
  const Bsdf a = make_bsdf("fiber_table", params, ctx);
  EXPECT_GT(progress_calls, 0);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir / ".weft-cache"))
    if (e.path().extension() == ".exr") files.push_back(e.path());  // beside it: the entry's lock
  ASSERT_EQ(files.size(), 1u);
  const auto table = TabulatedBsdfTable::read_exr(files[0]);
  EXPECT_EQ(table.resolution, 4);
  EXPECT_EQ(table.metadata.at("spec_hash"), fiber_spec_hash_hex(load_fiber_spec("white-cotton")));
  const auto written = fs::last_write_time(files[0]);
  progress_calls = 0;
  const Bsdf b = make_bsdf("fiber_table", params, ctx);
  EXPECT_EQ(progress_calls, 0);  // no second bake
  EXPECT_EQ(fs::last_write_time(files[0]), written);
  const Vec3 wo = normalize(Vec3{0.2, 0.1, 0.9}), wi = normalize(Vec3{-0.3, 0.2, 0.8});
  EXPECT_EQ(a.eval(wo, wi), b.eval(wo, wi));
  // Another photon count is another table.
  make_bsdf("fiber_table", {{"spec", "white-cotton"}, {"resolution", 4}, {"photons", 300}}, ctx);
  int tables = 0;
  for (const auto& e : fs::directory_iterator(dir / ".weft-cache"))
    tables += e.path().extension() == ".exr";
  EXPECT_EQ(tables, 2);
  // Bad parameters name the field.
  for (const auto& [bad, field] : std::vector<std::pair<nlohmann::json, std::string>>{
           {{{"spec", "white-cotton"}, {"file", "x.exr"}}, "spec"},
           {{{"spec", "white-cotton"}, {"photons", 0.5}}, "photons"},
           {{{"spec", "white-cotton"}, {"resolution", 1}}, "resolution"},
           {{{"file", "x.exr"}, {"photons", 10}}, "photons"},
           {{{"spec", "no-such-preset"}}, "spec"}}) {
    try {
      make_bsdf("fiber_table", bad, ctx);
      ADD_FAILURE() << bad.dump();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("materials.seat.params." + field), std::string::npos)
          << e.what();
    }
  }
}

TEST(FiberTableBake, SpecBakedForASceneInARelativeFolderLoadsItsOwnCache) {
  // A scene named by a relative path with a folder in it ("scenes/x.json") has a relative base
  // folder. Its cache entry must be found where it was written (the base folder was once
  // prepended twice: "scenes/scenes/.weft-cache/..."), and errors name the key the user wrote.
  namespace fs = std::filesystem;
  const fs::path rel = fs::path("weft-relative-bake") / "scenes";
  fs::remove_all(rel.parent_path());
  fs::create_directories(rel);
  MaterialContext ctx;
  ctx.base_dir = rel;
  ctx.source_file = (rel / "scene.json").string();
  ctx.field_prefix = "materials.seat.params";
  ctx.fiber_tables = fiber_table_resolver();
  const nlohmann::json params = {{"spec", "white-cotton"}, {"resolution", 2}, {"photons", 64}};
  EXPECT_NO_THROW(make_bsdf("fiber_table", params, ctx));
  ASSERT_TRUE(fs::is_directory(rel / ".weft-cache"));
  EXPECT_FALSE(fs::exists(rel / rel));
  // Without a resolver, a spec is a clear error at the spec field.
  MaterialContext bare = ctx;
  bare.fiber_tables = nullptr;
  try {
    make_bsdf("fiber_table", params, bare);
    ADD_FAILURE() << "a spec without a resolver was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("materials.seat.params.spec"), std::string::npos)
        << e.what();
  }
  fs::remove_all(rel.parent_path());
}

namespace {

// Runs cached_fiber_table in 'n' processes started together; returns how many baked, and whether
// every one succeeded.
std::pair<int, bool> bake_in_processes(int n, const std::filesystem::path& dir) {
  FiberTableBakeOptions o;
  o.resolution = 2;
  o.photons_per_band = 2000;
  o.spectral = false;
  o.threads = 1;
  const FiberSpec spec = load_fiber_spec("white-cotton");
  std::vector<pid_t> children;
  for (int i = 0; i < n; ++i) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      int code = 2;
      try {
        bool baked = false;
        const auto file = cached_fiber_table(dir, spec, o, no_progress(), &baked);
        TabulatedBsdfTable::read_exr(file);  // whole, whoever wrote it
        code = baked ? 1 : 0;
      } catch (...) {
      }
      ::_exit(code);
    }
    children.push_back(pid);
  }
  int baked = 0;
  bool ok = true;
  for (pid_t pid : children) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) > 1) ok = false;
    baked += WIFEXITED(status) && WEXITSTATUS(status) == 1;
  }
  return {baked, ok};
}

}  // namespace

TEST(FiberTableBake, ConcurrentProcessesBakeACacheEntryOnce) {
  // Two and four processes that need the same table at once: one bakes, the others wait for it
  // and reuse it (no failed rename, no second bake), and a truncated entry is baked again.
  namespace fs = std::filesystem;
  for (int n : {2, 4}) {
    const fs::path dir = fs::temp_directory_path() / ("weft-cache-race-" + std::to_string(n));
    fs::remove_all(dir);
    const auto [baked, ok] = bake_in_processes(n, dir);
    EXPECT_TRUE(ok) << n << " processes";
    EXPECT_EQ(baked, 1) << n << " processes";
    // Exactly one entry (and its lock), no temporaries left behind.
    int tables = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
      EXPECT_NE(e.path().filename().string().rfind(".tmp-", 0), 0u) << e.path();
      tables += e.path().extension() == ".exr";
    }
    EXPECT_EQ(tables, 1);
  }
  // Damage the entry: the next process bakes it again instead of failing.
  const fs::path dir = fs::temp_directory_path() / "weft-cache-race-2";
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".exr") fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
  const auto [baked, ok] = bake_in_processes(1, dir);
  EXPECT_TRUE(ok);
  EXPECT_EQ(baked, 1);
}

TEST(FiberTableBake, SurfaceAlbedoTableResolvesGrazingAngles) {
  // The fraction of light the rough surface reflects (its complement enters the fiber), against a
  // Monte Carlo estimate from the same lobe's sample weights (the lobe's own estimator: 400 000
  // samples, standard error below 0.2 %), for smooth and rough lobes down to 89.9 degrees.
  for (const double alpha : {0.01, 0.05, 0.35}) {
    const SurfaceAlbedoTable table(MicrofacetModel::kBeckmann, alpha, 1.557);
    const CookTorranceBsdf ct{{MicrofacetModel::kBeckmann, alpha}, 1.557, Rgb(1.0)};
    for (const double c : {0.002, 0.005, 0.01, 0.03, 0.1, 0.5, 1.0}) {
      const Vec3 w{safe_sqrt(1 - c * c), 0, c};
      Rng rng(3);
      double sum = 0, sum2 = 0;
      const int n = 400000;
      for (int k = 0; k < n; ++k) {
        const auto s = ct.sample(w, {rng.uniform(), rng.uniform()}, rng.uniform());
        const double x = s ? s->weight.r : 0.0;
        sum += x, sum2 += x * x;
      }
      const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
      EXPECT_NEAR(table(c), mean, 4 * se + 0.005 * mean) << "alpha " << alpha << " cos " << c;
    }
  }
}

TEST(FiberTableBake, ReciprocityCheckDetectsAMismatchedBoundary) {
  // The check above can fail: light entering through the rough interface but leaving through the
  // smooth Fresnel boundary (a mismatch like the one docs/fiber-bsdf.md records) is not
  // reciprocal, and the same bakes show it (6 bins beyond 4.5 standard errors at alpha 0.8).
  FiberSpec spec = rough_dielectric(test_spec(6, 0.04, 0.003));
  spec.roughness_alpha = 0.8;
  const MediumBand mb = compute_medium_band(spec, 10);
  FiberBandPhysics ph = fiber_band_physics(spec, mb);
  ph.interior =
      smooth_fiber_physics(TransportMedium{mb.mu_a_per_um, mb.mu_s_per_um, mb.host_n, mb.phase},
                           spec.fiber_radius_um, 1.0)
          .interior;
  EXPECT_GT(far_field_reciprocity(ph, 50000).outliers, 1);
}

TEST(FiberTableBake, RoughDielectricBoundaryDirectAndBssrdfRoutesAgree) {
  // Both routes launch through enter_fiber, so the rough boundary reaches the paper's route too:
  // the same comparison as DirectAndBssrdfRoutesAgreeWithinStatisticalError, with the rough
  // dielectric boundary.
  const FiberSpec spec = rough_dielectric(test_spec(20, 0.10, 0.01));
  const MediumBand mb = compute_medium_band(spec, 16);
  const FiberBandPhysics ph = fiber_band_physics(spec, mb);
  const auto [direct, bssrdf] = bake_both_routes(ph);
  EXPECT_LE(count_outliers(direct.mean, direct.se, bssrdf.mean, bssrdf.se, 4.5), 1);
}

// weft bake fiber's plan (fiber_bake_request.h): the front end's spelling of an option names it,
// the spec is read before the options are checked (so a missing spec wins), and a shard's range
// and a whole bake's defaults come from the spec and route.
TEST(FiberTableBake, RequestPlanNamesTheFrontEndsOptionsInOrder) {
  FiberBakeRequest r;
  r.spec = "red-cotton";
  r.resolution = 1;
  EXPECT_NE(error_of([&] { plan_fiber_bake(r); }).find("field 'resolution': must be in [2, 32]"),
            std::string::npos);
  r.option_prefix = "--";
  r.resolution = 4;
  r.surface_samples = 0;
  EXPECT_NE(error_of([&] { plan_fiber_bake(r); }).find("field '--surface-samples'"),
            std::string::npos);
  r.spec = "no-such-preset";
  EXPECT_NE(error_of([&] { plan_fiber_bake(r); }).find("no-such-preset"), std::string::npos);
  r.spec = "red-cotton";
  r.surface_samples.reset();
  r.route = "bssrdf";
  r.estimator = "nee";
  // The options' consistency is the bake's own check (before any photon, as the CLI had it).
  const FiberBakePlan nee = plan_fiber_bake(r);
  EXPECT_NE(error_of([&] { run_fiber_bake(nee); }).find("field 'estimator'"), std::string::npos);
  r.estimator.reset();
  const FiberBakePlan p = plan_fiber_bake(r);
  EXPECT_EQ(p.options.estimator, FiberExitEstimator::kPlain);  // the route's default
  EXPECT_EQ(p.options.entry, FiberEntrySampling::kRandom);
  EXPECT_TRUE(p.shard.whole());
  EXPECT_EQ(p.bands.last - p.bands.first, static_cast<uint64_t>(kNumBands));
  r.route = "direct";
  r.shard = "1/2";
  r.output = "part.weft-part";
  const FiberBakePlan s = plan_fiber_bake(r);
  EXPECT_EQ(s.options.estimator, FiberExitEstimator::kNextEvent);
  EXPECT_EQ(s.bands.first, shard_units(kNumBands, {1, 2}).first);
  EXPECT_EQ(s.job.command, "bake fiber");
}
