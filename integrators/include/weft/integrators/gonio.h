#pragma once
// Virtual gonioreflectometer (Voloboy et al. 2010, section 4): a parallel light of irradiance E
// at (theta_i, phi_i) and a list of view directions. For each view the sample is rendered with an
// orthographic camera that frames its bounding box exactly, the radiance of the camera samples
// that hit the sample is summed (the mask), and the radiance coefficient is
//   beta = L_sample / L_white,  L_sample = sum / footprint,  L_white = E cos(theta_i) / pi,
// the radiance of an ideal white Lambertian reflector under the same light. The white reference
// is also rendered (every material of the sample replaced by white Lambert) as a check. The
// paper's normalization scales every beta so that beta at normal incidence and view equals a
// given value. beta_err is the standard error from the per-pixel sample variance.
//
// Angles are in degrees in the description's AngleFrame. View directions lie in the plane at
// azimuth phi_v (default phi_i, the plane of incidence); as in the paper's Fig. 7, a view zenith
// theta_v > 0 lies on the mirror side (azimuth phi_v + 180) and theta_v < 0 on the light's side.
// The scene's own lights and environment are not used; emissive surfaces still emit.
//
// The scene description's "sweep" section sets the instrument (every key optional; the defaults
// are GonioSettings{}):
//
//   "sweep": {"sample": NAME, "light_zenith_deg": t, "light_azimuth_deg": p, "irradiance": c,
//             "view_zenith_deg": [list] | {"from": a, "to": b, "step": s}, "view_azimuth_deg": p,
//             "normalize_to": c, "white_check": true, "width": 64, "height": 64, "spp": 16}
//
// and its "render" section the path tracer's max_depth, rr_depth, seed and spectral (a spectral
// sweep needs a grey irradiance, RenderSettings::spectral).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/integrators/path_tracer.h"
#include "weft/materials/registry.h"
#include "weft/scenes/description.h"

namespace weft {

struct GonioSettings {
  std::string sample;  // object name (empty: every mesh)
  double light_zenith_deg = 0, light_azimuth_deg = 0;
  Rgb irradiance{1.0};
  std::vector<double> view_zenith_deg;
  std::optional<double> view_azimuth_deg;  // default: the light's azimuth (plane of incidence)
  std::optional<Rgb> normalize_to;
  bool white_check = true;
  // Each view's image: the sweep's own settings, not the "render" section's (a sweep renders many
  // small views of one object, a render one large image).
  int width = 64, height = 64, spp = 16;
  // The path tracer's own settings, shared with renders.
  int max_depth = RenderSettings{}.max_depth, rr_depth = RenderSettings{}.rr_depth;
  uint64_t seed = RenderSettings{}.seed;
  int threads = RenderSettings{}.threads;
  bool spectral = RenderSettings{}.spectral;
  // A sweep split over processes or resumed renders some of its units (gonio_unit_count): unit v
  // < views is view v, the last one, when there is one, the normal-incidence reference that the
  // normalization needs when no row gives it. Empty: every unit, then the normalization.
  std::optional<std::vector<size_t>> units;
};

// Units of a sweep: its views, plus one for the normal-incidence reference when normalizing and
// no row is at normal incidence and view.
size_t gonio_unit_count(const GonioSettings& settings);

// GonioSettings{} with the description's "sweep" section and the path tracer's settings of its
// "render" section applied. Unknown keys and bad values are weft::Error naming the description's
// file and the key's path ("sweep.view_zenith_deg.step").
GonioSettings gonio_settings_from(const SceneDescription& desc);

// Signed view zenith / azimuth (degrees) to a unit direction towards the viewer.
Vec3 gonio_view_direction(const AngleFrame& frame, double view_zenith_deg, double view_azimuth_deg);

struct GonioRow {
  size_t view = 0;  // index into view_zenith_deg
  double view_zenith_deg = 0, view_azimuth_deg = 0;
  Rgb sum;                  // sum over pixels of the radiance of samples hitting the sample
  double footprint_px = 0;  // pixels covered by the sample (sum of coverage)
  Rgb beta, beta_err_rgb;
  double beta_err = 0;       // standard error of the channel mean of beta
  std::optional<Rgb> white;  // rendered white reference / (E cos theta_i / pi)
  std::optional<Rgb> beta_norm;
};

// Rays and dropped samples of every view's render together; cancelled: the rows are partial.
struct GonioResult : RenderOutcome {
  std::vector<GonioRow> rows;
  double light_zenith_deg = 0, light_azimuth_deg = 0;
  Rgb l_white;                       // E cos(theta_i) / pi
  std::optional<Rgb> beta_normal;    // beta at normal incidence and view (when normalizing)
  std::optional<Rgb> normalization;  // the factor applied to every beta
};

// 'fiber_tables' makes the fiber tables that materials name by spec (null: such materials are an
// error).
// 'on_unit' is called after every unit rendered, with the result so far (a checkpoint).
GonioResult run_gonio(const SceneDescription& desc, const GonioSettings& settings,
                      const ProgressCallback& progress = no_progress(),
                      const FiberTableResolver& fiber_tables = {},
                      const std::function<void(const GonioResult&)>& on_unit = {});

// The normalization of a sweep whose rows (every view, in order) and beta_normal (when it took
// the reference unit) are there: sets normalization and every row's beta_norm. Does nothing
// without settings.normalize_to.
void normalize_gonio(GonioResult& result, const GonioSettings& settings);

// One row per view: view_zenith_deg, view_azimuth_deg, light_zenith_deg, light_azimuth_deg,
// sum_r, sum_g, sum_b, footprint_px, beta_r, beta_g, beta_b, beta_err, beta_err_r, beta_err_g,
// beta_err_b, white_r, white_g, white_b (nan without the check), and beta_norm_r/g/b when
// normalizing.
std::string gonio_csv(const GonioResult& result);

}  // namespace weft
