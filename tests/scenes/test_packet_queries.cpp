// Packet queries (RenderScene::intersect_coherent, occluded_coherent): each ray of a packet gets,
// bit for bit, the answer its own query gets, on every kind of geometry a render meets: meshes
// with vertex normals, instanced copies of a periodic sample (mesh shifts), round fibers and
// fiber tubes; in packets of every size up to RenderScene::kPacketRays.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "lambert_scene.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/scenes/description.h"
#include "weft/scenes/render_scene.h"
#include "weft/scenes/weave.h"

using namespace weft;

namespace {

using weft::testing::all_lambert;
using weft::testing::kWifDir;

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}
bool same_bits(const Vec3& a, const Vec3& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}
// Every field a hit sets (render_scene.h SurfaceHit).
bool same_hit(const SurfaceHit& a, const SurfaceHit& b) {
  return same_bits(a.t, b.t) && same_bits(a.p, b.p) && same_bits(a.ng, b.ng) &&
         same_bits(a.shading.s, b.shading.s) && same_bits(a.shading.t, b.shading.t) &&
         same_bits(a.shading.n, b.shading.n) && same_bits(a.uv.x, b.uv.x) &&
         same_bits(a.uv.y, b.uv.y) && a.shape == b.shape && a.prim == b.prim &&
         a.fiber == b.fiber && a.segment == b.segment && same_bits(a.offset, b.offset) &&
         same_bits(a.lift_front, b.lift_front) && same_bits(a.lift_back, b.lift_back);
}

struct Tally {
  int hits = 0, misses = 0, blocked = 0, open = 0;
};

// Packets of n = 1, 2, ..., kPacketRays rays, each packet a pixel's worth: rays from a point
// above the sample (a box of half-sizes hx, hz in x and z, from height 'top'), down in one
// direction to within a few degrees, some of them tilted so far that they miss. Each packet's
// hits are compared with intersect()'s, then shadow rays from the mesh hits towards one direction
// with occluded()'s.
Tally compare_packets(const RenderScene& scene, double hx, double hz, double top, uint64_t seed) {
  constexpr int kMax = RenderScene::kPacketRays;
  Rng rng(seed);
  Tally tally;
  for (int packet = 0; packet < 120; ++packet) {
    const int n = 1 + packet % kMax;
    const Vec3 o{(2 * rng.uniform() - 1) * hx, top, (2 * rng.uniform() - 1) * hz};
    const double a = 2 * kPi * rng.uniform(),
                 c = packet % 7 == 0 ? 0.05 : 0.3 + 0.7 * rng.uniform();
    std::array<Ray, kMax> rays;
    for (int i = 0; i < n; ++i) {
      const double ai = a + 0.05 * (rng.uniform() - 0.5), ci = c + 0.02 * (rng.uniform() - 0.5);
      const double si = std::sqrt(std::max(0.0, 1 - ci * ci));
      const Vec3 jitter{1e-5 * (rng.uniform() - 0.5), 0, 1e-5 * (rng.uniform() - 0.5)};
      rays[i] = {o + jitter, normalize(Vec3{si * std::cos(ai), -ci, si * std::sin(ai)}), 1e300};
    }
    std::array<SurfaceHit, kMax> hits;
    std::array<SurfaceHit*, kMax> into;
    for (int i = 0; i < kMax; ++i) into[i] = &hits[i];
    bool found[kMax];
    scene.intersect_coherent({rays.data(), size_t(n)}, into.data(), found);
    // Half the packets' light above the sample, half below it (through the cloth).
    const Vec3 to_light =
        normalize(Vec3{0.3, packet % 2 == 0 ? 1.0 : -1.0, 0.2 * (packet % 3 - 1)});
    std::array<Ray, kMax> shadow;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      SurfaceHit one;
      const bool found_one = scene.intersect(rays[i], &one);
      EXPECT_EQ(found[i], found_one) << "packet " << packet << " ray " << i;
      if (!found_one || !found[i]) {
        tally.misses += !found_one;
        continue;
      }
      ++tally.hits;
      EXPECT_TRUE(same_hit(one, hits[i])) << "packet " << packet << " ray " << i;
      // Fibers' shadow rays ignore their fiber, which a packet query does not: from meshes only.
      if (!one.on_fiber()) shadow[m++] = {one.spawn_origin(to_light), to_light, 1e300};
    }
    bool blocked[kMax];
    scene.occluded_coherent({shadow.data(), size_t(m)}, blocked);
    for (int i = 0; i < m; ++i) {
      const bool one = scene.occluded(shadow[i].o, shadow[i].d, shadow[i].tmax);
      EXPECT_EQ(blocked[i], one) << "packet " << packet << " shadow ray " << i;
      ++(one ? tally.blocked : tally.open);
    }
  }
  return tally;
}

}  // namespace

TEST(PacketQueries, AMeshWithVertexNormalsAnswersAsOneByOne) {
  WeaveParams p;
  p.yarns = 8, p.segments = 64, p.sides = 8;
  SceneDescription d;
  for (auto& m : make_weave(p))
    d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(m)));
  ASSERT_FALSE(d.meshes[0]->normals.empty());
  const RenderScene scene(all_lambert(d));
  const Bounds3 b = scene.bounds();
  const Vec3 h = 0.5 * (b.hi - b.lo);  // the patch is centred on the origin, normal along y
  const Tally t = compare_packets(scene, 0.9 * h.x, 0.9 * h.z, b.hi.y + 0.1 * h.x, 1);
  EXPECT_GT(t.hits, 500);  // the comparisons above ran
  EXPECT_GT(t.misses, 10);
  EXPECT_GT(t.blocked, 20);
  EXPECT_GT(t.open, 20);
}

TEST(PacketQueries, InstancedCopiesFibersAndTubesAnswerAsOneByOne) {
  WeaveOptions o;
  o.wif = (kWifDir / "54235-plain.wif").string();
  const WovenSample y = make_woven_sample(o);
  const double px = y.summary.period_x_mm * 1e-3, pz = y.summary.period_z_mm * 1e-3;
  const double top = y.summary.y_max_mm * 1e-3 + 1e-4;
  const RenderScene inst(all_lambert(tiled_woven_description(y, 1, 1, "tiled", true)));
  const Tally ti = compare_packets(inst, 0.8 * px, 0.8 * pz, top, 2);
  EXPECT_GT(ti.hits, 500);
  EXPECT_GT(ti.blocked, 20);
  EXPECT_GT(ti.open, 20);

  WeaveOptions f = o;
  f.detail = "fiber";
  const SceneDescription fibers =
      all_lambert(tiled_woven_description(make_woven_sample(f), 0, 0, "tiled"));
  for (const auto type : {FiberGeometry::Type::curves, FiberGeometry::Type::tubes}) {
    RenderSceneOptions options;
    options.fiber_geometry = FiberGeometry{type};
    const RenderScene scene(fibers, options);
    const Tally tf = compare_packets(scene, 0.4 * px, 0.4 * pz, top, 3);
    EXPECT_GT(tf.hits, 300) << "tubes " << (type == FiberGeometry::Type::tubes);
  }
}
