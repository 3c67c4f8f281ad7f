#pragma once
// The white furnace of a convex sphere: a Lambert sphere of albedo rho (the unit sphere at the
// origin, the scene's shape 0) in a constant environment of radiance 1 has radiance rho everywhere
// (pbrt-v4 src/pbrt/cpu/integrators_test.cpp, "furnace" scenes: albedo 1 gives radiance 1). Shared
// by the constant environment (test_furnace.cpp) and the environment map
// (test_environment_map.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_util.h"
#include "weft/core/math.h"
#include "weft/integrators/path_tracer.h"
#include "weft/scenes/render_scene.h"

namespace weft::testing {

inline const char* mode_name(LightSampling m) {
  return m == LightSampling::mis           ? "mis"
         : m == LightSampling::lights_only ? "lights_only"
                                           : "bsdf_only";
}

// With MIS and each of its strategies alone: 40000 paths from 'eye' (on the +z axis) through
// points of the sphere's silhouette disc all hit the sphere, and their mean radiance is the
// albedo within 4 standard errors, each at most 1 % of it (so that the check can fail).
inline void expect_furnace_sphere_radiance(const RenderScene& scene, const Vec3& eye,
                                           double albedo) {
  for (LightSampling mode :
       {LightSampling::mis, LightSampling::lights_only, LightSampling::bsdf_only}) {
    SCOPED_TRACE(std::string(mode_name(mode)) + " albedo " + std::to_string(albedo));
    RenderSettings s;
    s.max_depth = 64;
    s.sampling = mode;
    s.seed = 7;
    // Only rays that hit the sphere: aim at points on the sphere's silhouette disc.
    RayCounts rays;
    int missed = 0;
    const SampleMean e = sample_mean(40000, [&](int i) {
      Rng rng(s.seed, uint64_t(i));
      const double r = 0.95 * std::sqrt(rng.uniform()), phi = 2 * kPi * rng.uniform();
      const Vec3 target{r * std::cos(phi), r * std::sin(phi), 0};
      int64_t first = -1;
      const double v =
          trace_path(scene, {eye, normalize(target - eye)}, s, rng, rays, &first).average();
      missed += first != 0;
      return v;
    });
    ASSERT_EQ(missed, 0);
    EXPECT_LT(e.std_error, 0.01 * albedo);
    EXPECT_NEAR(e.mean, albedo, 4 * e.std_error + 1e-12);
  }
}

}  // namespace weft::testing
