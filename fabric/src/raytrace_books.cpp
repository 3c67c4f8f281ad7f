// The fabric ray trace's parts that stand outside the trace itself (fabric_raytrace.h): the fiber
// directions the summations see, the scene's memory estimate, the options' checks and the energy
// books summed from each incident bin's.
#include <algorithm>
#include <cmath>
#include <string>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/raytrace_steps.h"
#include "weft/scenes/render_scene.h"

namespace weft {

std::optional<VisibleFiberTangents> visible_fiber_tangents(const WovenSample& sample,
                                                           const ProgressCallback& progress,
                                                           int rays_per_side) {
  if (rays_per_side < 1 || rays_per_side > 4096)
    throw Error("", "rays_per_side", "must lie in [1, 4096]");
  const raytrace::RepeatSlab r = raytrace::repeat_slab_of(sample);
  const std::optional<SceneDescription> geometry = raytrace::tiled_geometry(sample, progress);
  if (!geometry) return std::nullopt;
  RenderSceneOptions build;
  build.build_progress = progress;
  const RenderScene scene(*geometry, build);
  if (scene.cancelled()) return std::nullopt;
  VisibleFiberTangents out;
  // A row of rays at a time between polls: at most 4096 rays, milliseconds at any scene size.
  const uint64_t rows = 2 * uint64_t(rays_per_side);
  for (const bool from_above : {true, false})
    for (int i = 0; i < rays_per_side; ++i) {
      const uint64_t row = (from_above ? 0 : rays_per_side) + uint64_t(i);
      if (!progress({"visible fibers", row, rows, "rows of rays"})) return std::nullopt;
      for (int k = 0; k < rays_per_side; ++k) {
        const Vec3 p{r.x0 + r.px * (i + 0.5) / rays_per_side,
                     from_above ? r.y1 + 1e-6 : r.y0 - 1e-6,
                     r.z0 + r.pz * (k + 0.5) / rays_per_side};
        SurfaceHit h;
        if (scene.intersect({p, {0, from_above ? -1.0 : 1.0, 0}, 1e300}, &h))
          (from_above ? out.top : out.bottom).push_back(raytrace::world_to_cloth(h.shading.s));
      }
    }
  return out;
}

std::vector<Vec3> visible_fiber_tangents(const WovenSample& sample, bool from_above,
                                         int rays_per_side) {
  VisibleFiberTangents both = *visible_fiber_tangents(sample, no_progress(), rays_per_side);
  return from_above ? std::move(both.top) : std::move(both.bottom);
}

namespace {
// Measured with peak RSS (docs/PERFORMANCE.md, "Memory of the fabric scene"): what weft holds
// before the scene (the fiber table, the program), and Embree's acceleration structure with its
// build's scratch per triangle and per round curve segment at high build quality.
constexpr double kFabricSceneBaseBytes = 150e6;
constexpr double kFabricSceneBvhBytesPerTriangle = 100;
constexpr double kFabricSceneBvhBytesPerSegment = 100;
}  // namespace

double fabric_scene_bytes(const WovenSampleSize& z) {
  // Yarn tubes. The sample's mesh per vertex: position, normal, tangent (xyzw), uv floats; per
  // triangle three indices; its vectors grown by push_back hold up to twice that, the
  // description's copy exactly that. Embree's copy: 12 B per vertex, 12 B per triangle.
  constexpr double kVertexBytes = 12 * sizeof(float), kTriangleBytes = 3 * sizeof(uint32_t);
  constexpr double kEmbreeVertexBytes = 12, kEmbreeTriangleBytes = 12;
  // Embree's acceleration structure over the triangles, with its build's scratch, at high build
  // quality (render_scene.cpp): measured, docs/PERFORMANCE.md.
  constexpr double kBvhTriangleBytes = kFabricSceneBvhBytesPerTriangle;
  const double mesh = z.vertices * kVertexBytes + z.triangles * kTriangleBytes;
  const double tubes = 3 * mesh + z.vertices * kEmbreeVertexBytes +
                       z.triangles * (kEmbreeTriangleBytes + kBvhTriangleBytes);
  // Fibers, copied nine times: per point 4 floats in the sample and its copies, 4 floats in
  // Embree's buffer; per segment its index (4 B), neighbour flags (1 B), the segment index
  // (first point and curve, 8 B) and the acceleration structure.
  constexpr double kPointBytes = 4 * sizeof(float), kEmbreePointBytes = 4 * sizeof(float);
  constexpr double kSegmentBytes = 4 + 1 + 8 + kFabricSceneBvhBytesPerSegment;
  // The points the sample will hold (the sections it is predicted to end in), not the packing
  // estimate: 8452.wif's fibers fall back to vertical sections, 4.0 M points made against 7.26 M
  // estimated, and its estimate was 3 times the measured peak.
  const double points = z.made_curve_points > 0 ? z.made_curve_points : z.curve_points;
  const double segments = z.made_curve_points > 0 ? z.made_curve_segments : z.curve_segments;
  const double fibers = points * kPointBytes +
                        9 * (points * (kPointBytes + kEmbreePointBytes) + segments * kSegmentBytes);
  return kFabricSceneBaseBytes + tubes + fibers;
}

namespace {
// Measured (2026-12-05, the shared 2-core machine, CPU time from /usr/bin/time -v), on the draft
// 8452.wif at fiber detail, which woven_sample_size counts as 7.26 M points and segments (at the
// default packing; built at the densest packing that fits, 4.0 M): `weft weave` 49 s, so 6.4 us
// per point counted; `weft bake fabric --method raytrace -R 1 --samples 1` 72 s, so 23 s for the
// scene, 3.2 us per segment counted. `weft verify --quality draft` on it took 325 s, 60 s above
// that and the poplin's rates for its particles and camera samples (12 s): its rays took 6 times
// as long as on a small sample. On the bundled poplin (4 930 segments), the twill draft (13 300)
// and the plain draft tiled 6 x 6 (124 000) the rays took no longer (29-35 s of CPU each), so the
// factor grows from there, taken as the structure's depth grows: with the logarithm of the
// segments, 0.85 per doubling.
constexpr double kMakeSecondsPerCurvePoint = 6.4e-6;
// A nonwoven mat's making follows its placement work (WovenSampleSize): fitted (2026-12-06, the
// same machine, `weft weave` of the bundled felt at thicknesses 1.0-2.4 mm and tiles 1.2-3.4 mm,
// 0.75-32 s of CPU), 4.4 us per crossing fiber searched and 0.47 ns per copy glanced at, within
// 0.83-1.13 of the measured time on all six.
constexpr double kMakeSecondsPerCrossingCheck = 4.4e-6;
constexpr double kMakeSecondsPerCopyCheck = 4.7e-10;
constexpr double kBuildSecondsPerSegment = 3.2e-6;
constexpr double kSegmentsOfUnslowedRays = 1.24e5;
constexpr double kRayFactorPerDoubling = 0.85;
}  // namespace

FabricSceneSeconds fabric_scene_seconds(const WovenSampleSize& z) {
  FabricSceneSeconds c;
  c.make = z.placement_crossing_checks > 0
               ? z.placement_crossing_checks * kMakeSecondsPerCrossingCheck +
                     z.placement_copy_checks * kMakeSecondsPerCopyCheck
               : z.curve_points * kMakeSecondsPerCurvePoint;
  c.build = z.curve_segments * kBuildSecondsPerSegment;
  c.per_ray_factor = 1 + kRayFactorPerDoubling *
                             std::max(0.0, std::log2(z.curve_segments / kSegmentsOfUnslowedRays));
  return c;
}

namespace {

// A narrow light is a light of its own: it replaces the bins' beams and what is worked out per bin.
void validate_narrow_light(const FabricRaytraceOptions& o) {
  const NarrowLight& n = *o.narrow_light;
  const auto in = [](double x, double lo, double hi) { return x >= lo && x <= hi; };
  if (!in(n.theta_deg, 0, 89))
    throw Error("", "narrow_light.theta_deg", "must lie in [0, 89] (light from above)");
  if (!in(n.azimuth_deg, -360, 360))
    throw Error("", "narrow_light.azimuth_deg", "must lie in [-360, 360]");
  const auto range = [](double lo, double hi) {
    return "must lie in [" + ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) + "]";
  };
  if (!in(n.half_angle_deg, 0, NarrowLight::kMaxHalfAngleDeg))
    throw Error("", "narrow_light.half_angle_deg", range(0, NarrowLight::kMaxHalfAngleDeg));
  if (!in(n.band_deg, NarrowLight::kMinBandDeg, NarrowLight::kMaxBandDeg))
    throw Error("", "narrow_light.band_deg",
                range(NarrowLight::kMinBandDeg, NarrowLight::kMaxBandDeg));
  if (!in(n.bin_deg, NarrowLight::kMinBinDeg, NarrowLight::kMaxBinDeg))
    throw Error("", "narrow_light.bin_deg",
                range(NarrowLight::kMinBinDeg, NarrowLight::kMaxBinDeg));
  if (o.first_bin != 0 || o.bin_count != 0)
    throw Error("", "narrow_light", "traces its own bin: leave first_bin and bin_count 0");
  if (o.straight_through != StraightThrough::sampled)
    throw Error("", "narrow_light",
                "needs the straight-through light sampled (its exact part is a bin's beam's)");
  if (o.sheen_h_resolution != 0 || o.weave_positions_u != 0)
    throw Error("", "narrow_light", "takes no sheen and no weave tally");
}

}  // namespace

void FabricRaytraceOptions::validate() const {
  if (resolution < 1 || resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (particles_per_bin < 1 || particles_per_bin > (uint64_t{1} << 36))
    throw Error("", "samples", "particles per incident bin must lie in [1, 2^36]");
  if (max_scatterings < 1) throw Error("", "max_scatterings", "must be >= 1");
  if (!(roulette_threshold > 0 && roulette_threshold < 1))
    throw Error("", "roulette_threshold", "must lie in (0, 1)");
  if (!(split_threshold > roulette_threshold) || !std::isfinite(split_threshold))
    throw Error("", "split_threshold", "must be finite and above roulette_threshold");
  if (max_copies_per_particle < 1 || max_copies_per_particle > (1 << 20))
    throw Error("", "max_copies_per_particle", "must lie in [1, 2^20]");
  if (threads < 0) throw Error("", "threads", "must be >= 0");
  if (next_event_rays < 0 || next_event_rays > kMaxNextEventRays)
    throw Error("", "next_event_rays",
                "must lie in [0, " + std::to_string(kMaxNextEventRays) + "]");
  if (launch_lattice < 1 || launch_lattice > kMaxLaunchLattice)
    throw Error("", "launch_lattice", "must lie in [1, " + std::to_string(kMaxLaunchLattice) + "]");
  if (next_event_rays > 0 && channel_sampling == ChannelSampling::mean)
    throw Error("", "next_event_rays", "the next-event estimate needs the hero estimator");
  const int bins = DirectionGrid{resolution}.bins();
  if (first_bin < 0 || bin_count < 0 || first_bin + bin_count > bins)
    throw Error("", "bin_count", "incident bins must lie in [0, " + std::to_string(bins) + ")");
  validate_weave_options(*this);
  if (sheen_h_resolution != 0) {
    HalfVectorLobe::check_shape(sheen_h_resolution, sheen_window, "", "sheen_h_resolution",
                                "sheen_window");
    if (sheen_light_resolution != 0)
      HalfVectorLobe::check_light_resolution(resolution, sheen_light_resolution, "",
                                             "sheen_light_resolution");
  } else if (sheen_light_resolution != 0) {
    throw Error("", "sheen_light_resolution", "sizes the sheen's light bins: it needs a sheen");
  }
  if (narrow_light) validate_narrow_light(*this);
}

int NarrowLight::plane_bins() const {
  return static_cast<int>(std::floor(2 * kMaxPlaneDeg / bin_deg + 1e-9));
}

void FabricBinBooks::add(const FabricBinBooks& o) {
  launched += o.launched, exited += o.exited, absorbed += o.absorbed, lost += o.lost;
  roulette_net += o.roulette_net;
  particles += o.particles, scatterings += o.scatterings, wraps += o.wraps, splits += o.splits;
  roulette_kills += o.roulette_kills, tube_passes += o.tube_passes;
  inside_hits += o.inside_hits;
}

void fabric_raytrace_totals(FabricRaytraceResult& r) {
  FabricBinBooks all;
  std::vector<double> noise2, signal2;
  for (const FabricBinBooks& b : r.bin_books) {
    all.add(b);
    noise2.resize(std::max(noise2.size(), b.noise2.size()), 0.0);
    signal2.resize(noise2.size(), 0.0);
    for (size_t c = 0; c < b.noise2.size() && c < b.signal2.size(); ++c) {
      noise2[c] += b.noise2[c];
      signal2[c] += b.signal2[c];
    }
  }
  r.particles = all.particles, r.scatterings = all.scatterings, r.wraps = all.wraps;
  r.splits = all.splits;
  r.inside_hits = all.inside_hits;
  r.roulette_kills = all.roulette_kills, r.tube_passes = all.tube_passes;
  r.splits_per_bin.assign(r.bin_books.size(), 0);
  r.roulette_kills_per_bin.assign(r.bin_books.size(), 0);
  for (size_t b = 0; b < r.bin_books.size(); ++b) {
    r.splits_per_bin[b] = r.bin_books[b].splits;
    r.roulette_kills_per_bin[b] = r.bin_books[b].roulette_kills;
  }
  r.exited = r.absorbed = r.lost = r.roulette_net = 0;
  if (all.launched > 0) {
    r.exited = all.exited / all.launched;
    r.lost = all.lost / all.launched;
    r.roulette_net = all.roulette_net / all.launched;
    r.absorbed = all.absorbed / all.launched;
  }
  // Each channel on its own, and all together as weft compare's rel_rms sums them.
  double all_noise2 = 0, all_signal2 = 0;
  r.relative_noise_per_channel.assign(noise2.size(), 0.0);
  for (size_t c = 0; c < noise2.size(); ++c) {
    r.relative_noise_per_channel[c] = signal2[c] > 0 ? std::sqrt(noise2[c] / signal2[c]) : 0;
    all_noise2 += noise2[c];
    all_signal2 += signal2[c];
  }
  r.relative_noise = all_signal2 > 0 ? std::sqrt(all_noise2 / all_signal2) : 0.0;
}

}  // namespace weft
