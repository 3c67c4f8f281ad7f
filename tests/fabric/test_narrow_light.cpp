// A narrow light and its plane's exits (FabricRaytraceOptions::narrow_light): the analytic flat
// sheets, the side of the mirror, determinism and the options it refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "flat_sheet.h"
#include "raytrace_test_util.h"
#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/recorded_paths.h"

using namespace weft;
using namespace weft::testing;

namespace {

FabricRaytraceOptions narrow_options(double theta_deg, double azimuth_deg, double half_angle_deg,
                                     uint64_t particles) {
  FabricRaytraceOptions o = options(4, particles);
  o.straight_through = StraightThrough::sampled;
  o.narrow_light = NarrowLight{.theta_deg = theta_deg,
                               .azimuth_deg = azimuth_deg,
                               .half_angle_deg = half_angle_deg,
                               .band_deg = 10,
                               .bin_deg = 5};
  return o;
}

}  // namespace

// A flat sheet whose "fiber" is Lambertian (rho / pi above the point) is a Lambertian surface
// (FabricRaytrace.FlatLambertSheetIsLambertian): under any light, collimated or a cone, f is rho /
// pi in every bin of the plane, on either side of the normal, within the stated standard error.
// The bins hold f per unit theta' phi' (each exit weighted by 1 / (wo.z cos theta')), so the
// normalisation by the power launched and the bins' angles, and that weight, are what is checked.
TEST(NarrowLight, FlatLambertSheetIsLambertianInTheLightsPlane) {
  const double rho = 0.6;
  const auto fiber = fiber_table(
      4, [&](const Vec3& wo, const Vec3& wi) { return wo.z > 0 && wi.z > 0 ? rho / kPi : 0.0; });
  for (double half : {0.0, 5.0}) {
    const FabricRaytraceOptions o = narrow_options(40, 30, half, 200000);
    const auto r = raytrace_fabric_table(flat_sheet(), fiber, o);
    const NarrowLight& n = *o.narrow_light;
    ASSERT_EQ(r.plane_f.size(), static_cast<size_t>(n.plane_bins()) * 3);
    ASSERT_EQ(n.plane_bins(), 35);  // 178 / 5
    double z2 = 0;
    int tested = 0;
    for (int k = 0; k < n.plane_bins(); ++k) {
      // Expected exits in the bin: N rho / pi over the bin of cos^2 theta' cos phi'.
      const double a = deg_to_rad(n.plane_angle_deg(k)), h = 0.5 * deg_to_rad(n.bin_deg);
      const double cos2 = 0.5 * (2 * h + 0.5 * (std::sin(2 * (a + h)) - std::sin(2 * (a - h))));
      const double count = 200000 * rho / kPi * cos2 * 2 * std::sin(0.5 * deg_to_rad(n.band_deg));
      if (count < 25) continue;
      for (int c = 0; c < 3; ++c) {
        const double f = r.plane_f[k * 3 + c], se = r.plane_f_se[k * 3 + c];
        EXPECT_NEAR(f, rho / kPi, 5 * se) << half << " " << k;
        EXPECT_GT(se, 0) << k;
        // The channels share their particles and the sheet is grey: they agree bit for bit.
        EXPECT_EQ(f, r.plane_f[k * 3]) << k;
      }
      const double z = (r.plane_f[k * 3] - rho / kPi) / r.plane_f_se[k * 3];
      z2 += z * z, ++tested;
    }
    EXPECT_GE(tested, 28) << half;                   // all but the most grazing bins
    EXPECT_LT(std::sqrt(z2 / tested), 1.6) << half;  // the standard error is honest
    // Only the light's own bin is traced.
    EXPECT_EQ(r.particles, 200000u);
  }
}

// A glossy sheet (a lobe about the half vector's angle to the normal, sigma 8 degrees, in the
// "fiber" table) reflects about the mirror: in the light's plane its peak lies on the mirror's
// side (theta' = -theta_i) within the fiber table's bins (R 8, about 11 degrees), far above the
// light's own side: a sign turned in the plane's angle would swap them.
TEST(NarrowLight, AGlossySheetPeaksOnTheMirrorsSide) {
  const double sigma = deg_to_rad(8);
  const auto fiber = fiber_table(8, [&](const Vec3& wo, const Vec3& wi) {
    if (!(wo.z > 0 && wi.z > 0)) return 0.0;
    const double th = std::acos(std::min(1.0, normalize(wo + wi).z));
    return 0.02 + 2 * std::exp(-th * th / (2 * sigma * sigma));
  });
  const FabricRaytraceOptions o = narrow_options(35, 60, 0, 100000);
  const auto r = raytrace_fabric_table(flat_sheet(), fiber, o);
  const NarrowLight& n = *o.narrow_light;
  int peak = 0;
  for (int k = 0; k < n.plane_bins(); ++k)
    if (r.plane_f[k * 3] > r.plane_f[peak * 3]) peak = k;
  // The sheet's exits are drawn from the table's cell averages: the peak is a plateau some 25
  // degrees wide (measured: 1.21-1.27 from -36.5 to -26.5 degrees), its largest bin within 12.
  EXPECT_NEAR(n.plane_angle_deg(peak), -35, 12);
  const auto bin_at = [&](double a) {
    return static_cast<int>((a + NarrowLight::kMaxPlaneDeg) / n.bin_deg);
  };
  EXPECT_GT(r.plane_f[bin_at(-35) * 3], 20 * r.plane_f[bin_at(35) * 3]);  // measured: 46
}

TEST(NarrowLight, BitIdenticalAtOneAndTwoThreads) {
  const auto fiber = reciprocal_fiber(4);
  FabricRaytraceOptions o = narrow_options(50, 0, 1, 3000);
  o.resolution = 8;
  o.next_event_rays = 2;
  const WovenSample sample = default_sample("fiber");
  o.threads = 1;
  const auto a = raytrace_fabric_table(sample, fiber, o);
  o.threads = 2;
  const auto b = raytrace_fabric_table(sample, fiber, o);
  EXPECT_EQ(a.plane_f, b.plane_f);
  EXPECT_EQ(a.plane_f_se, b.plane_f_se);
  EXPECT_EQ(a.table.values, b.table.values);
  EXPECT_GT(*std::max_element(a.plane_f.begin(), a.plane_f.end()), 0);
  EXPECT_EQ(a.table.metadata.at("narrow_light"), "theta 50, azimuth 0, half angle 1 deg");
}

TEST(NarrowLight, ItsOptionsAreCheckedBeforeAnyWork) {
  const auto fiber = uniform_fiber(4, 0.1);
  const WovenSample sheet = flat_sheet();
  const auto refused = [&](FabricRaytraceOptions o, const char* what) {
    EXPECT_NE(error_of([&] { raytrace_fabric_table(sheet, fiber, o); }).find(what),
              std::string::npos)
        << what;
  };
  FabricRaytraceOptions o = narrow_options(40, 0, 0, 10);
  o.straight_through = StraightThrough::exact;  // a bin's beam's
  refused(o, "straight-through");
  o = narrow_options(40, 0, 0, 10);
  o.bin_count = 1;
  refused(o, "first_bin and bin_count");
  o = narrow_options(40, 0, 0, 10);
  o.sheen_h_resolution = 16;
  refused(o, "no sheen");
  o = narrow_options(95, 0, 0, 10);
  refused(o, "narrow_light.theta_deg");
  o = narrow_options(40, 0, 11, 10);
  refused(o, "narrow_light.half_angle_deg");
  o = narrow_options(40, 0, 0, 10);
  o.narrow_light->band_deg = std::nan("");
  refused(o, "narrow_light.band_deg");
  o = narrow_options(40, 0, 0, 10);
  o.narrow_light->bin_deg = 0;
  refused(o, "narrow_light.bin_deg");
  o = narrow_options(40, 0, 0, 10);
  EXPECT_NE(error_of([&] { record_fabric_paths(sheet, fiber, o); }).find("narrow_light"),
            std::string::npos);
}
