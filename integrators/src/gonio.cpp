#include "weft/integrators/gonio.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/integrators/masked_render.h"
#include "weft/scenes/render_scene.h"

namespace weft {
namespace {

struct ViewMeasure {
  Rgb sum;       // sum over pixels of the masked radiance (per-pixel sample means)
  Rgb mean;      // sum / footprint: the sample's mean radiance
  Rgb var_mean;  // variance of that mean
  double footprint = 0;
};

// The sample's mean radiance is a ratio estimator, R = sum(h x) / sum(h), with h = 1 for camera
// samples that hit the sample and x their radiance. Its variance follows from the residuals
// y = h (x - R) (delta method; Cochran, Sampling Techniques, 3rd ed., section 6.3), estimated from
// each pixel's sample variance. Edge pixels that are partly covered add no variance by themselves.
ViewMeasure measure(const MaskedRender& r, int spp) {
  ViewMeasure m;
  const size_t npx = r.coverage.size();
  double s[3] = {0, 0, 0}, fp = 0;
  for (size_t p = 0; p < npx; ++p) {
    fp += r.coverage[p];
    for (int c = 0; c < 3; ++c) s[c] += r.sum[3 * p + c];
  }
  m.sum = {s[0], s[1], s[2]};
  m.footprint = fp;
  const double R[3] = {s[0] / fp, s[1] / fp, s[2] / fp};
  double v[3] = {0, 0, 0};
  for (size_t p = 0; p < npx; ++p) {
    const double h = r.coverage[p];
    for (int c = 0; c < 3; ++c) {
      // Per-sample moments of y over the pixel's spp samples (the stored sums are divided by spp).
      const double hx = r.sum[3 * p + c], hx2 = r.sum_sq[3 * p + c];
      const double ey = hx - R[c] * h;
      const double ey2 = hx2 - 2 * R[c] * hx + R[c] * R[c] * h;
      // Unbiased sample variance of y, divided by spp for the pixel mean.
      v[c] += spp > 1 ? std::max(0.0, (ey2 - ey * ey) * spp / (spp - 1)) / spp : NAN;
    }
  }
  m.mean = {R[0], R[1], R[2]};
  m.var_mean = Rgb(v[0], v[1], v[2]) / (fp * fp);
  return m;
}

Rgb divide(const Rgb& a, const Rgb& b) {
  return {a.r / b.r, a.g / b.g, a.b / b.b};
}

// Signed view zeniths in degrees: a list, or {from, to, step} (inclusive).
std::vector<double> read_angle_list(ParamReader& p, const std::string& key) {
  const auto& v = p.at(key);
  std::vector<double> out;
  if (v.is_array()) {
    for (size_t i = 0; i < v.size(); ++i)
      out.push_back(p.check_number(v[i], p.field(key) + "[" + std::to_string(i) + "]", -90, 90));
  } else if (v.is_object()) {
    ParamReader r(v, p.file(), p.field(key));
    const double a = r.number("from", -90, 90), b = r.number("to", -90, 90),
                 s = r.number("step", 1e-6, 180);
    r.finish();
    if (b < a) throw Error(p.file(), p.field(key), "needs from <= to");
    // Counted before the list is built: a tiny step would ask for 10^8 views (hours of work).
    const double views = std::floor((b - a) / s + 1e-9) + 1;
    if (views > 100000)
      throw Error(p.file(), r.field("step"),
                  "gives " + ParamReader::fmt(views) + " views, more than 100000");
    const long n = static_cast<long>(views) - 1;
    for (long i = 0; i <= n; ++i) out.push_back(a + s * i);
  } else {
    throw Error(p.file(), p.field(key), "must be a list of angles or {from, to, step}");
  }
  if (out.empty()) throw Error(p.file(), p.field(key), "is empty");
  return out;
}

std::string fmt(double v) {
  if (std::isnan(v)) return "nan";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

GonioSettings gonio_settings_from(const SceneDescription& desc) {
  GonioSettings g;
  const RenderSettings r = render_settings_from(desc);
  g.max_depth = r.max_depth;
  g.rr_depth = r.rr_depth;
  g.seed = r.seed;
  g.spectral = r.spectral;
  if (!desc.sweep) return g;
  ParamReader p(*desc.sweep, desc.source, "sweep");
  constexpr double kMax = kMaxDescriptionRadiometric;
  g.sample = p.string("sample", g.sample);
  g.light_zenith_deg = p.number("light_zenith_deg", g.light_zenith_deg, 0.0, 89.9);
  g.light_azimuth_deg = p.number("light_azimuth_deg", g.light_azimuth_deg, -360.0, 360.0);
  g.irradiance = p.rgb("irradiance", g.irradiance, 1e-12, kMax);
  if (p.has("view_zenith_deg")) g.view_zenith_deg = read_angle_list(p, "view_zenith_deg");
  if (p.has("view_azimuth_deg")) g.view_azimuth_deg = p.number("view_azimuth_deg", -360.0, 360.0);
  if (p.has("normalize_to")) g.normalize_to = p.rgb("normalize_to", 1e-12, kMax);
  g.white_check = p.boolean("white_check", g.white_check);
  g.width = static_cast<int>(p.integer("width", g.width, 1, 16384));
  g.height = static_cast<int>(p.integer("height", g.height, 1, 16384));
  g.spp = static_cast<int>(p.integer("spp", g.spp, 1, 1 << 20));
  p.finish();
  return g;
}

Vec3 gonio_view_direction(const AngleFrame& frame, double view_zenith_deg,
                          double view_azimuth_deg) {
  const double azimuth = view_azimuth_deg + (view_zenith_deg > 0 ? 180.0 : 0.0);
  return frame.direction(deg_to_rad(std::abs(view_zenith_deg)), deg_to_rad(azimuth));
}

namespace {
bool needs_normal_render(const GonioSettings& g) {
  return g.normalize_to &&
         !(g.light_zenith_deg == 0 && std::find(g.view_zenith_deg.begin(), g.view_zenith_deg.end(),
                                                0.0) != g.view_zenith_deg.end());
}
}  // namespace

size_t gonio_unit_count(const GonioSettings& g) {
  return g.view_zenith_deg.size() + (needs_normal_render(g) ? 1 : 0);
}

void normalize_gonio(GonioResult& res, const GonioSettings& g) {
  if (!g.normalize_to) return;
  if (!needs_normal_render(g)) {
    for (const auto& row : res.rows)
      if (row.view_zenith_deg == 0) res.beta_normal = row.beta;
  }
  if (!res.beta_normal)
    throw Error("", "normalize_to", "the normal-incidence reference is missing");
  res.normalization = divide(*g.normalize_to, *res.beta_normal);
  for (auto& row : res.rows) row.beta_norm = row.beta * *res.normalization;
}

namespace {

void check_gonio_settings(const std::string& src, const GonioSettings& g) {
  if (!(g.light_zenith_deg >= 0 && g.light_zenith_deg < 90))
    throw Error(src, "light_zenith_deg", "must lie in [0, 90)");
  if (g.view_zenith_deg.empty()) throw Error(src, "view_zenith_deg", "no view directions");
  for (double v : g.view_zenith_deg)
    if (!(std::abs(v) < 90)) throw Error(src, "view_zenith_deg", "views must lie in (-90, 90)");
  if (!(g.irradiance.r > 0 && g.irradiance.g > 0 && g.irradiance.b > 0))
    throw Error(src, "irradiance", "must be positive in every channel");
  if (g.spectral && !g.irradiance.is_grey())
    throw Error(src, "irradiance",
                "a spectral sweep needs a grey irradiance (equal R, G and B: the same at every "
                "wavelength)");
  if (g.width < 1 || g.height < 1 || g.spp < 1)
    throw Error(src, "sweep", "width, height and spp must be positive");
}

// The instrument's light: parallel, from the given direction; the scene's own lights and
// environment are not part of the instrument.
Lights instrument_light(const SceneDescription& desc, const GonioSettings& g, double zenith_deg,
                        double azimuth_deg) {
  Lights l;
  l.directional.push_back(
      {desc.frame.direction(deg_to_rad(zenith_deg), deg_to_rad(azimuth_deg)), g.irradiance});
  return l;
}

// The scene with the sample's shapes ('sel') made a white Lambertian reflector.
RenderScene white_reference_scene(const SceneDescription& desc, const std::vector<uint8_t>& sel) {
  RenderSceneOptions opt;
  opt.override_shapes = sel;
  MaterialBinding white;
  white.type = "lambert";
  white.params = {{"reflectance", 1.0}};
  white.field = "white reference";
  opt.override_binding = white;
  return RenderScene(desc, opt);
}

// Which units of the sweep (gonio_unit_count) to run: g.units, or all.
std::vector<bool> wanted_units(const GonioSettings& g, const std::string& src) {
  std::vector<bool> wanted(gonio_unit_count(g), !g.units.has_value());
  if (g.units)
    for (size_t u : *g.units) {
      if (u >= wanted.size()) throw Error(src, "units", "a unit beyond the sweep's");
      wanted[u] = true;
    }
  return wanted;
}

RenderSettings view_render_settings(const GonioSettings& g) {
  RenderSettings rs;
  rs.width = g.width;
  rs.height = g.height;
  rs.spp = g.spp;
  rs.max_depth = g.max_depth;
  rs.rr_depth = g.rr_depth;
  rs.seed = g.seed;
  rs.threads = g.threads;
  rs.spectral = g.spectral;
  return rs;
}

// Renders the sweep's views one after another, reporting progress over all of them and adding
// each render's rays and dropped samples to the result.
class ViewRenderer {
 public:
  // The views of 'wanted' units of the sample 'sel' framed by 'box'.
  ViewRenderer(const SceneDescription& desc, const GonioSettings& g,
               const std::vector<uint8_t>& sel, const Bounds3& box, const std::vector<bool>& wanted,
               const ProgressCallback& progress, GonioResult& res)
      : desc_(desc),
        g_(g),
        sel_(sel),
        progress_(progress),
        res_(res),
        box_(box),
        rs_(view_render_settings(g)) {
    const size_t views = g.view_zenith_deg.size();
    const int per_view = g.white_check ? 2 : 1;
    for (size_t u = 0; u < wanted.size(); ++u)
      if (wanted[u]) renders_ += u < views ? per_view : 1;
  }

  // The sample's measure and its beta (mean radiance / l_white) seen from (zen, azi); nullopt
  // when cancelled.
  std::optional<std::pair<ViewMeasure, Rgb>> operator()(const RenderScene& scene, double zen,
                                                        double azi, const Rgb& l_white) {
    const Vec3 towards_viewer = gonio_view_direction(desc_.frame, zen, azi);
    // Film "up" follows the sample normal except near normal view.
    const Vec3 up_hint = std::abs(zen) > 5 ? desc_.frame.normal : desc_.frame.tangent;
    const Camera cam = frame_box_orthographic(box_, towards_viewer, up_hint);
    // Every view is the same number of samples (u.total) long.
    const MaskedRender r = render_masked(scene, cam, rs_, sel_, [&](const ProgressUpdate& u) {
      return progress_({"sweep", renders_done_ * u.total + u.done, renders_ * u.total, u.unit});
    });
    ++renders_done_;
    res_.rays += r.render.rays;
    res_.nonfinite_samples += r.render.nonfinite_samples;
    if (r.render.cancelled) return std::nullopt;
    const ViewMeasure m = measure(r, g_.spp);  // NaN when the sample is not seen at all
    return std::make_pair(m, divide(m.mean, l_white));
  }

 private:
  const SceneDescription& desc_;
  const GonioSettings& g_;
  const std::vector<uint8_t>& sel_;
  const ProgressCallback& progress_;
  GonioResult& res_;
  const Bounds3 box_;
  const RenderSettings rs_;
  uint64_t renders_ = 0, renders_done_ = 0;
};

// The row of view v at azimuth phi_v, with its white reference when 'white' is given; nullopt
// when cancelled.
std::optional<GonioRow> view_row(ViewRenderer& render_view, const GonioSettings& g, size_t v,
                                 double phi_v, const RenderScene& sample, const RenderScene* white,
                                 const Rgb& l_white) {
  const double zen = g.view_zenith_deg[v];
  GonioRow row;
  row.view = v;
  row.view_zenith_deg = zen;
  row.view_azimuth_deg = phi_v;
  const auto s = render_view(sample, zen, phi_v, l_white);
  if (!s) return std::nullopt;
  const auto& [m, beta] = *s;
  row.sum = m.sum;
  row.footprint_px = m.footprint;
  row.beta = beta;
  row.beta_err_rgb = {std::sqrt(m.var_mean.r) / l_white.r, std::sqrt(m.var_mean.g) / l_white.g,
                      std::sqrt(m.var_mean.b) / l_white.b};
  // Channel mean: channels of one sample are strongly correlated, so bound the error of the
  // mean by the mean of the errors (exact for perfectly correlated channels).
  row.beta_err = row.beta_err_rgb.average();
  if (white) {
    const auto w = render_view(*white, zen, phi_v, l_white);
    if (!w) return std::nullopt;
    row.white = w->second;
  }
  return row;
}

}  // namespace

GonioResult run_gonio(const SceneDescription& desc, const GonioSettings& g,
                      const ProgressCallback& progress, const FiberTableResolver& fiber_tables,
                      const std::function<void(const GonioResult&)>& on_unit) {
  const std::string src = desc.source;
  check_gonio_settings(src, g);
  const std::vector<uint8_t> sel = desc.select_object(g.sample);
  const Bounds3 box = desc.object_bounds(g.sample);
  const double phi_v = g.view_azimuth_deg.value_or(g.light_azimuth_deg);
  const Lights light = instrument_light(desc, g, g.light_zenith_deg, g.light_azimuth_deg);
  RenderSceneOptions sample_options;
  sample_options.material_progress = progress;
  sample_options.fiber_tables = fiber_tables;
  const RenderScene sample_scene = RenderScene(desc, sample_options).with_lights(light);
  std::optional<RenderScene> white_scene;
  if (g.white_check) white_scene = white_reference_scene(desc, sel).with_lights(light);

  // Normalization needs beta at normal incidence and view; reuse a row when the sweep has it.
  const size_t views = g.view_zenith_deg.size();
  const std::vector<bool> wanted = wanted_units(g, src);
  GonioResult res;
  ViewRenderer render_view(desc, g, sel, box, wanted, progress, res);
  res.light_zenith_deg = g.light_zenith_deg;
  res.light_azimuth_deg = g.light_azimuth_deg;
  const double cos_i = std::cos(deg_to_rad(g.light_zenith_deg));
  res.l_white = g.irradiance * (cos_i * kInvPi);

  for (size_t v = 0; v < views; ++v) {
    if (!wanted[v]) continue;
    const auto row = view_row(render_view, g, v, phi_v, sample_scene,
                              white_scene ? &*white_scene : nullptr, res.l_white);
    if (!row) {
      res.cancelled = true;
      return res;
    }
    res.rows.push_back(*row);
    if (on_unit) on_unit(res);
  }

  if (needs_normal_render(g) && wanted[views]) {
    const RenderScene normal_scene = sample_scene.with_lights(instrument_light(desc, g, 0, 0));
    const Rgb l_white00 = g.irradiance * kInvPi;
    const auto s = render_view(normal_scene, 0, 0, l_white00);
    if (!s) {
      res.cancelled = true;
      return res;
    }
    res.beta_normal = s->second;
    if (on_unit) on_unit(res);
  }
  if (!g.units) normalize_gonio(res, g);
  return res;
}

std::string gonio_csv(const GonioResult& r) {
  std::ostringstream os;
  os << "view_zenith_deg,view_azimuth_deg,light_zenith_deg,light_azimuth_deg,sum_r,sum_g,sum_b,"
        "footprint_px,"
        "beta_r,beta_g,beta_b,beta_err,beta_err_r,beta_err_g,beta_err_b,white_r,white_g,white_b";
  const bool norm = r.normalization.has_value();
  if (norm) os << ",beta_norm_r,beta_norm_g,beta_norm_b";
  os << "\n";
  for (const auto& row : r.rows) {
    const Rgb w = row.white.value_or(Rgb(NAN));
    os << fmt(row.view_zenith_deg) << ',' << fmt(row.view_azimuth_deg) << ','
       << fmt(r.light_zenith_deg) << ',' << fmt(r.light_azimuth_deg) << ',' << fmt(row.sum.r) << ','
       << fmt(row.sum.g) << ',' << fmt(row.sum.b) << ',' << fmt(row.footprint_px) << ','
       << fmt(row.beta.r) << ',' << fmt(row.beta.g) << ',' << fmt(row.beta.b) << ','
       << fmt(row.beta_err) << ',' << fmt(row.beta_err_rgb.r) << ',' << fmt(row.beta_err_rgb.g)
       << ',' << fmt(row.beta_err_rgb.b) << ',' << fmt(w.r) << ',' << fmt(w.g) << ',' << fmt(w.b);
    if (norm) {
      const Rgb b = row.beta_norm.value_or(Rgb(NAN));
      os << ',' << fmt(b.r) << ',' << fmt(b.g) << ',' << fmt(b.b);
    }
    os << "\n";
  }
  return os.str();
}

}  // namespace weft
