#pragma once
// Unidirectional path tracer over a RenderScene. At every surface, next-event estimation takes one
// sample of every light through the Light interface (lights.h); for area lights and the
// environment it is combined with BSDF sampling by multiple importance sampling (power heuristic,
// Veach 1997 ch. 9), delta lights have only that one strategy. Russian roulette after rr_depth
// bounces; shading in the mesh's tangent frame; two-sided (the BSDF sees wo below its normal and
// decides); transmission continues through the surface. Every random number of a camera sample
// comes from Rng(seed, pixel index, sample index) and tiles write disjoint pixels, so images are
// bit-identical at any thread count. The pixel index is that of the whole film, so a crop window
// holds the same bits as the same window of the whole render; a render cut short by its time
// limit after n whole passes holds the same bits as a render of n samples per pixel.
//
// Fibers (round curves or tubes) are shaded with their fiber BSDF as hair renderers shade a fiber
// with its BCSDF: a fiber table is the BSDF of the whole fiber (docs/fiber-bsdf.md), so a point B
// of a fiber is shaded without occlusion by its own fiber: the shadow rays of next-event
// estimation and the continuation ray that leave B ignore B's fiber (RenderScene's ignore_fiber),
// and light from behind B, through its own fiber, is the table's to account for. Every other
// fiber occludes and inter-reflects as any surface does. Triangles of meshes are unaffected.
//
// Spectral renders (RenderSettings::spectral): light is carried per wavelength band, all 33 on
// every path (as the fabric ray trace's particles carry them), not in RGB. Directions, lights and
// Russian roulette are drawn as in RGB (a table samples by its RGB mean, whose coverage keeps the
// density > 0 wherever any band is); the path's values are the materials' bands (bsdfs.h
// eval_bands: a spectral table's, or a grey colour's, the same at every band) and the lights'
// grey colour; each sample's radiance is reduced to linear sRGB through the D65 band weights (the
// one reduction of tables, spectrum.h). The mean is the per-band transport reduced after, which
// for light scattered many times in a coloured material differs from the RGB transport of the
// reduced table. The image is unclipped linear sRGB (a saturated spectrum can leave the gamut).
#include <cstdint>
#include <functional>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/integrators/image.h"
#include "weft/integrators/render_settings.h"
#include "weft/integrators/weave_level.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/render_scene.h"

namespace weft {

// The path tracer's revision, raised whenever a change alters its images for the same inputs:
// part of a split or resumed sweep's identity (parts of another revision are refused, not
// merged). 2: rays leaving a fiber pass through its continuation across a tile's side, which
// revision 1 took for a wall (render_scene.h intersect). 3: a fiber table read by cell is sampled
// by its cells' values (tabulated_bsdf.h; same mean, other bits).
inline constexpr int kPathTracerRevision = 3;

struct RayCounts {
  uint64_t camera = 0, bounce = 0, shadow = 0;
  uint64_t total() const { return camera + bounce + shadow; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera, bounce += o.bounce, shadow += o.shadow;
    return *this;
  }
};

// How a run of the renderer went, whatever it was run for (an image, a render job, a sweep of
// views): what every caller reports the same way.
struct RenderOutcome {
  RayCounts rays;
  uint64_t nonfinite_samples = 0;  // dropped (counted, never hidden)
  bool cancelled = false;          // the progress callback asked to stop; results are partial
};

// The per-pixel buffers of a render of settings 's' (its crop window's pixels when cropped): the
// image and each AOV pass (3 floats), a time-limited render's running sums (9 doubles), the sRGB
// preview (3 bytes) and a masked render's hit counts, sums and squares (3 + 3 doubles) and
// coverage (a float).
double render_bytes(const RenderSettings& s, bool preview, bool mask);

struct RenderResult : RenderOutcome {
  Image image;  // mean radiance per pixel, linear RGB (the crop window's pixels when cropped)
  // Samples per pixel in 'image': settings.spp, or fewer whole passes when the time limit ended
  // the render.
  int spp_done = 0;
  // The first surface each camera sample hits, averaged like 'image' (empty unless asked for):
  // its directional albedo for the direction to the camera (one BSDF sample per camera sample:
  // the sampled weight f cos / pdf, whose mean is the albedo), and its shading normal in world
  // space turned towards the camera. A camera ray that hits nothing adds zero to both.
  Image albedo, normal;
  // With RenderSettings::light_groups: per light of the scene (RenderScene::lights' order), the
  // mean radiance its own light gives, as 'image' (which is their sum).
  std::vector<Image> light_images;
  // The level each woven mesh was shaded at (weave_level.h); empty when the scene has none.
  std::vector<WeaveLevelChoice> weave_levels;
};

// After every camera sample: its pixel (row-major on the whole film, a crop window too), the shape
// (SurfaceHit::shape) its camera ray hit first (-1: none) and its radiance (0 for a dropped
// non-finite sample).
using SampleObserver = std::function<void(uint64_t pixel, int64_t first_mesh, const Rgb& radiance)>;
// Every ray handed to the scene: camera and bounce rays (shadow = false) and shadow rays (shadow =
// true, ending at ray.tmax).
using RayObserver = std::function<void(const Ray& ray, bool shadow)>;

// What instruments built on the renderer see of a render (the gonioreflectometer's object mask in
// masked_render.h, the render benchmark's ray log); the path tracer keeps nothing for them. An
// empty observer costs one test where it would be called. Both are called from the worker
// threads: every sample of a pixel from one thread and in sample order, so per-pixel state needs
// no lock; the ray observer is called concurrently and in trace order within a tile.
struct RenderObservers {
  SampleObserver on_sample;
  RayObserver on_ray;
};

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& settings,
                    const ProgressCallback& progress = no_progress(),
                    const RenderObservers& observers = {});

// Radiance arriving along 'ray' (one path sample). 'first_mesh' receives the shape the ray hits
// first (-1 for none); 'on_ray' sees every ray traced. With settings.spectral the path carries
// every band and returns their linear sRGB (RenderScene::check_spectral first). Exposed for tests
// of the estimator itself.
Rgb trace_path(const RenderScene& scene, const Ray& ray, const RenderSettings& settings, Rng& rng,
               RayCounts& rays, int64_t* first_mesh = nullptr, const RayObserver* on_ray = nullptr);

}  // namespace weft
