#pragma once
// The renders of the sample in weft verify's report (paper's Figs. 8-9; verify_render.cpp): the
// flat patch with each model's fabric table, and the woven sample's fibers with each model's
// fiber table.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/math.h"
#include "weft/core/progress.h"
#include "weft/core/spectrum.h"
#include "weft/integrators/image.h"
#include "weft/scenes/description.h"
#include "weft/scenes/weave.h"
#include "weft/verify/settings.h"

namespace weft {

// One render of a flat patch of cloth (docs/verify.md "Renders"): the model's fabric table (or the
// measured BRDF) on a 1 m square, a parallel light of irradiance pi at normal incidence, from the
// viewer's side ("reflection") or from behind ("transmission"), an orthographic camera at 30 deg
// from the normal. A flat patch under a parallel light has one radiance, L = f E cos theta_i =
// pi f = beta for this (view, light): the image is that colour, as the renderer shades it.
struct VerifyRender {
  std::string stem;           // file name without extension, e.g. "render-reflection-computed"
  std::string kind;           // "patch" (the fabric table) or "weave" (the fibers, below)
  std::string model;          // "computed", "classic", "measured"
  std::string configuration;  // "reflection", "transmission"
  std::string caption;
  Image image;         // linear sRGB radiance
  Rgb patch_radiance;  // patch: mean over the central half of the film (wholly inside the patch)
  Rgb mean;            // mean over the whole image
};

// The geometry of every render (one place for the numbers the captions and tests quote).
inline constexpr double kVerifyRenderViewZenithDeg = 30;
inline constexpr double kVerifyRenderIrradiance = kPi;  // L = beta
// The PNGs: linear radiance times 1 (a white Lambertian patch would be 1, white), clipped to
// [0, 1], sRGB transfer curve (image.h write_png_preview); no other tone mapping. EXR: linear.
inline constexpr double kVerifyRenderExposure = 1;
inline constexpr const char* kVerifyRenderSetup =
    "A flat 1 m square of cloth with the model's fabric table (the measured BRDF's neural fit for "
    "the measurement), lit by a parallel light of irradiance pi at normal incidence, from the "
    "viewer's side (reflection) or from behind (transmission), seen by an orthographic camera 30 "
    "deg from the normal; the path tracer of weft render. Under a parallel light a flat patch has "
    "one radiance, beta = pi f for that view and light, so each image is one colour. PNG: linear "
    "radiance times 1 (a white Lambertian patch would be white), clipped to [0, 1], sRGB transfer "
    "curve, no other tone mapping; EXR: linear sRGB radiance.";

// The patch render's scene, built in memory (verify_render.cpp): a flat 1 m square of cloth, the
// object and material "cloth" bound to 'material' (its relative paths resolve against
// 'base_dir'), lit by a parallel light of irradiance kVerifyRenderIrradiance at normal incidence
// from the viewer's side or from behind ('transmission'), seen by an orthographic camera
// kVerifyRenderViewZenithDeg from the normal that frames the patch, with the render settings
// (render_size, render_spp, seed).
SceneDescription verify_render_scene(const nlohmann::json& material, bool transmission,
                                     const VerifySettings& settings,
                                     const std::filesystem::path& base_dir);

// The fiber-level renders (docs/verify.md "Renders"): the woven sample's fibers, as Embree round
// curves, every fiber with the model's fiber table, shaded by the renderer as any scene's fibers
// (RenderScene, path_tracer.h: the whole-fiber table, rays leaving a fiber ignore it, every other
// fiber occludes and inter-reflects). Lit as the patch (a parallel light of irradiance pi at
// normal incidence, from the viewer's side or from behind) and seen from the same direction (30
// deg from the normal, azimuth 180 deg from the warp) by an orthographic camera whose film is
// whole repeats of the cloth: repeats_z along the film's width (the weft direction) and repeats_x
// along its height (the warp, foreshortened by cos 30 deg), chosen so that each side comes near
// kVerifyWeaveFrameMm. Over whole repeats the film's mean is the cloth's mean radiance for that
// view and light, which the fabric table (the patch render) estimates too. The sample is tiled
// (weave.h tiled_woven_description) so that the cloth reaches a repeat past the film on every side.
inline constexpr double kVerifyWeaveFrameMm = 1.4;
struct VerifyWeaveFrame {
  int repeats_x = 1, repeats_z = 1;  // whole repeats on the film's height and width
  double half_width_m = 0, half_height_m = 0;
  int width = 1, height = 1;       // pixels: the longer side 'size', square to within a pixel
  int copies_x = 1, copies_z = 1;  // tiled copies on each side of the sample's own
};
// weft::Error when the sample has no period or size < 1.
VerifyWeaveFrame verify_weave_frame(const WeaveSummary& sample, int size);
// The scene (in memory): the tiled fibers, materials "warp" and "weft" bound to 'material' (its
// relative paths resolve against 'base_dir'), two lights (the first on the viewer's side, the
// second behind the cloth: rendered with light groups, one pass gives the reflection and the
// transmission images), the camera and the render settings (weave_render_size,
// weave_render_spp, seed). weft::Error when the sample is not at fiber detail.
// The fibers' copies poll 'progress' (near the limit of 3e7 points they take seconds each);
// nothing when it said stop.
std::optional<SceneDescription> verify_weave_scene(const WovenSample& sample,
                                                   const nlohmann::json& material,
                                                   const VerifySettings& settings,
                                                   const std::filesystem::path& base_dir,
                                                   const ProgressCallback& progress);
inline constexpr const char* kVerifyWeaveRenderSetup =
    "The woven sample at fiber detail, tiled, every fiber an Embree round curve with the model's "
    "fiber table (shaded as weft render shades fibers: the whole-fiber table, no occlusion by the "
    "fiber a ray leaves, occlusion and inter-reflection by every other fiber; the table read by "
    "cell, as the fabric ray trace reads it, so the two are one transport), lit and seen as "
    "the patch above: a parallel light of irradiance pi at normal incidence, from the viewer's "
    "side (reflection) or from behind (transmission), an orthographic camera 30 deg from the "
    "normal whose film spans whole repeats, so the image's mean is the cloth's mean radiance for "
    "that view and light. Black: gaps between the yarns. Same tone mapping as above.";

// Renders what the report holds: computed and classic fabric tables in both configurations, the
// measured BRDF (report.measured_nbrdf) in reflection; and where the report holds the sample at
// fiber detail, the fibers with the computed and classic fiber tables in both configurations
// (verify_weave_scene; stems render-weave-CONFIGURATION-MODEL). The tables are written into
// 'folder' first (fabric-computed.exr, fabric-classic.exr, fiber-classic.exr in RGB;
// fiber-computed.exr as the model has it, spectral, and rendered as a spectral render), where the
// renderer reads them as any scene's fabric_table or fiber_table; the images are returned, not
// written. Each render's scene build and render poll 'progress' (a publication render of a large
// sample takes minutes); when it says stop, the renders end there, '*cancelled' (when given) is
// set and the renders returned are only those finished.
struct VerifyReport;
std::vector<VerifyRender> render_verify_samples(const std::filesystem::path& folder,
                                                const VerifyReport& report,
                                                const ProgressCallback& progress = no_progress(),
                                                bool* cancelled = nullptr);

}  // namespace weft
