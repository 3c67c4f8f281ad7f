#pragma once
// What the fiber bake's tests share (test_fiber_table_bake.cpp, test_fiber_bake_estimators.cpp):
// small specs, per-cell statistics over independent bakes and their comparison.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "transport_test_util.h"
#include "weft/core/math.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft::testing {

// A minimal spec: cotton host with air voids; optional dye and overrides.
inline FiberSpec test_spec(double radius_um = 8, double void_fraction = 0.02, double dye_per_um = 0,
                           double void_radius_um = 0.3) {
  const std::string json = R"({"name": "test", "fiber_radius_um": )" + std::to_string(radius_um) +
                           R"(, "roughness": {"distribution": "ggx", "alpha": 0.3},
    "host": {"n": 1.557, "absorption_per_um": )" +
                           std::to_string(dye_per_um) + R"(},
    "species": [{"name": "voids", "n": 1.0, "k": 0.0, "volume_fraction": )" +
                           std::to_string(void_fraction) + R"(,
      "size": {"distribution": "monodisperse", "radius_um": )" +
                           std::to_string(void_radius_um) + R"(}}]})";
  return parse_fiber_spec(json, "test-spec");
}

// The transport engine's numerical extremes lie beyond what a user's spec may ask for
// (fiber_spec.h bounds the radius to [0.5, 500] um): made from a valid spec, then changed.
inline FiberSpec extreme_spec(double radius_um, double void_fraction, double dye_per_um,
                              double void_radius_um = 0.3) {
  FiberSpec s = test_spec(8, void_fraction, dye_per_um, std::min(void_radius_um, 1.0));
  s.fiber_radius_um = radius_um;
  for (auto& sp : s.species) sp.size.radius_um = void_radius_um;
  return s;
}

// Mean and standard error per cell over K independent bakes of one band.
struct CellStats {
  std::vector<double> mean, se;
};
template <class BakeFn>
CellStats cell_stats(int k, const BakeFn& bake) {
  std::vector<double> s, s2;
  for (int i = 0; i < k; ++i) {
    const FiberBandTable t = bake(static_cast<uint64_t>(1000 + i));
    if (s.empty()) s.assign(t.f.size(), 0.0), s2.assign(t.f.size(), 0.0);
    for (size_t c = 0; c < t.f.size(); ++c) s[c] += t.f[c], s2[c] += t.f[c] * t.f[c];
  }
  CellStats st;
  for (size_t c = 0; c < s.size(); ++c) {
    const double m = s[c] / k;
    st.mean.push_back(m);
    st.se.push_back(std::sqrt(std::max(0.0, s2[c] / k - m * m) / (k - 1)));
  }
  return st;
}

// Number of cells where |a - b| exceeds z standard errors (cells with both means 0 skipped).
inline int count_outliers(const std::vector<double>& a, const std::vector<double>& sa,
                          const std::vector<double>& b, const std::vector<double>& sb, double z) {
  int n = 0;
  for (size_t c = 0; c < a.size(); ++c) {
    if (a[c] == 0 && b[c] == 0) continue;
    const double se = std::sqrt(sa[c] * sa[c] + sb[c] * sb[c]);
    if (std::abs(a[c] - b[c]) > z * se + 1e-12) ++n;
  }
  return n;
}

// The direct and the BSSRDF route's cell statistics over 5 bakes each of band physics 'ph' at
// R = 3 (18 x 18 cells), the BSSRDF route at its default grid.
struct RouteStats {
  CellStats direct, bssrdf;
};
inline RouteStats bake_both_routes(const FiberBandPhysics& ph) {
  FiberBakeSettings s = weft::testing::bake_settings(3, 60000, 2);
  const int k = 5;
  RouteStats r;
  r.direct = cell_stats(k, [&](uint64_t seed) {
    s.seed = seed;
    return bake_fiber_band_direct(ph, s, nullptr);
  });
  r.bssrdf = cell_stats(k, [&](uint64_t seed) {
    s.seed = seed + 100;
    return bake_fiber_band_bssrdf(ph, s, BssrdfRouteSettings{}, nullptr);
  });
  return r;
}

// Two estimators of one table, judged alike (the tests of the bake's options): cell by cell at most
// one normalised difference beyond 4.5 standard errors and their RMS in [0.8, 1.4] (a bias of one
// standard error in every cell lifts it to 1.5), and the exit and absorbed fractions within 4.5
// standard errors of each other. 'label' names the estimator in the failures.
inline void expect_same_table(const CellStats& a, const CellStats& b,
                              const std::vector<double>& exit_a, const std::vector<double>& exit_b,
                              const std::vector<double>& absorbed_a,
                              const std::vector<double>& absorbed_b, int label) {
  const auto mean_se = [](const std::vector<double>& v) {
    double s = 0, s2 = 0;
    for (double x : v) s += x, s2 += x * x;
    const double m = s / v.size();
    return std::pair{m, std::sqrt(std::max(0.0, s2 / v.size() - m * m) / (v.size() - 1))};
  };
  EXPECT_LE(count_outliers(a.mean, a.se, b.mean, b.se, 4.5), 1) << label;
  double z2 = 0;
  int n = 0;
  for (size_t c = 0; c < a.mean.size(); ++c) {
    const double se = std::hypot(a.se[c], b.se[c]);
    if (!(se > 0)) continue;
    z2 += sqr((a.mean[c] - b.mean[c]) / se), ++n;
  }
  ASSERT_GT(n, 100) << label;
  const double rms = std::sqrt(z2 / n);
  EXPECT_GT(rms, 0.8) << label;
  EXPECT_LT(rms, 1.4) << label;
  for (const auto& [va, vb] : {std::pair{&exit_a, &exit_b}, std::pair{&absorbed_a, &absorbed_b}}) {
    const auto [ma, sa] = mean_se(*va);
    const auto [mb, sb] = mean_se(*vb);
    EXPECT_NEAR(ma, mb, 4.5 * std::hypot(sa, sb)) << label << ": " << sa << " " << sb;
  }
}

// The summed variance of a table's cell means.
inline double cell_noise(const CellStats& c) {
  double v = 0;
  for (double e : c.se) v += e * e;
  return v;
}

}  // namespace weft::testing
