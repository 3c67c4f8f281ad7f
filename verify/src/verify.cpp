#include "weft/verify/verify.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <system_error>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/install_paths.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/classic_fiber.h"

#ifndef WEFT_DATA_DIR
#define WEFT_DATA_DIR ""
#endif

namespace weft {
namespace {


std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

double parse_number(const std::string& text, const std::string& file, const std::string& field) {
  if (const auto v = finite_number(text)) return *v;
  throw Error(file, field, "'" + text + "' is not a finite number");
}

nlohmann::json metrics_json(const CurveMetrics& m) {
  return {{"rms_log", m.rms_log},
          {"rms_rel", m.rms_rel},
          {"points", m.points},
          {"excluded", m.excluded}};
}

nlohmann::json rgb_json(const Rgb& c) {
  return nlohmann::json::array({c.r, c.g, c.b});
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Batch k of a model's ray trace: its own stream, from the run's seed (core/hash.h).
uint64_t batch_seed(uint64_t seed, const std::string& model, int k) {
  return fnv1a64(model + ":" + std::to_string(seed) + ":" + std::to_string(k));
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o.push_back(c);
    }
  }
  return o;
}

std::string fmt(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

}  // namespace

// ---- Measurement ---------------------------------------------------------------------------

MeasuredInplane read_measured_inplane(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw Error(file, "", "cannot open the measured in-plane table");
  std::string line;
  std::vector<std::string> header;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.rfind("\"#", 0) == 0) continue;
    header = split_csv(line);
    break;
  }
  if (header.empty()) throw Error(file, "", "no header line (empty table)");
  const std::vector<std::string> needed = {"theta_i_deg", "theta_o_deg", "nbrdf_beta_R",
                                           "nbrdf_beta_G", "nbrdf_beta_B"};
  std::array<size_t, 5> col{};
  for (size_t k = 0; k < needed.size(); ++k) {
    const auto it = std::find(header.begin(), header.end(), needed[k]);
    if (it == header.end()) throw Error(file, needed[k], "missing column");
    col[k] = static_cast<size_t>(it - header.begin());
  }
  std::map<double, std::map<double, Rgb>> rows;  // theta_i -> view (paper's sign) -> beta
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const auto f = split_csv(line);
    const std::string where = "line " + std::to_string(line_no);
    if (f.size() != header.size())
      throw Error(file, where,
                  std::to_string(f.size()) + " fields where the header has " +
                      std::to_string(header.size()));
    std::array<double, 5> v{};
    for (size_t k = 0; k < 5; ++k) v[k] = parse_number(f[col[k]], file, where + " " + needed[k]);
    if (v[0] < 0 || v[0] >= 90) throw Error(file, where + " theta_i_deg", "must lie in [0, 90)");
    if (v[1] <= -90 || v[1] >= 90)
      throw Error(file, where + " theta_o_deg", "must lie in (-90, 90)");
    for (size_t k = 2; k < 5; ++k)
      if (v[k] < 0) throw Error(file, where + " " + needed[k], "a radiance coefficient is >= 0");
    // The table's theta_o is negative on the mirror side, the paper's view positive (0.0 - x:
    // no negative zero).
    auto& curve = rows[v[0]];
    if (!curve.emplace(0.0 - v[1], Rgb(v[2], v[3], v[4])).second)
      throw Error(file, where, "duplicate row for this (theta_i_deg, theta_o_deg)");
  }
  if (rows.empty()) throw Error(file, "", "no data rows");
  MeasuredInplane m;
  m.file = file;
  for (const auto& [ti, views] : rows) {
    MeasuredCurve c;
    c.theta_i_deg = ti;
    for (const auto& [v, b] : views) {
      c.view_deg.push_back(v);
      c.beta.push_back(b);
    }
    m.curves.push_back(std::move(c));
  }
  return m;
}

std::filesystem::path bundled_measured_inplane() {
  std::string tried;
  const auto p = find_installed_file(WEFT_DATA_DIR, "materials",
                                     "measured/merl-red-fabric/inplane.csv", &tried);
  if (p.empty())
    throw Error("merl-red-fabric/inplane.csv", "--measured",
                "the bundled measurement is not found (tried: " + tried + ")");
  return p;
}

// ---- Tables in the plane of incidence ---------------------------------------------------------

std::vector<Rgb> inplane_beta(const TabulatedBsdfTable& t, double theta_i_deg,
                              const std::vector<double>& views_deg, int azimuths) {
  if (t.channels != 3) throw Error("", "channels", "inplane_beta needs an RGB table");
  if (azimuths < 1) throw Error("", "azimuths", "must be >= 1");
  std::vector<Rgb> out(views_deg.size());
  std::array<double, 3> f{};
  const double ti = deg_to_rad(theta_i_deg);
  for (size_t k = 0; k < views_deg.size(); ++k) {
    const double v = deg_to_rad(views_deg[k]);
    Rgb sum;
    for (int a = 0; a < azimuths; ++a) {
      const double phi = 2 * kPi * a / azimuths;
      const Vec3 wi{std::sin(ti) * std::cos(phi), std::sin(ti) * std::sin(phi), std::cos(ti)};
      const Vec3 wo{-std::sin(v) * std::cos(phi), -std::sin(v) * std::sin(phi), std::cos(v)};
      t.interpolate(wo, wi, f);
      sum += Rgb(f[0], f[1], f[2]);
    }
    out[k] = sum * (kPi / azimuths);
  }
  return out;
}

TabulatedBsdfTable table_to_rgb(const TabulatedBsdfTable& t, GamutClip* clip) {
  if (t.channels == 3) return t;
  if (t.channels != kNumBands) throw Error("", "channels", "neither RGB nor 33 bands");
  TabulatedBsdfTable o;
  o.resolution = t.resolution;
  o.channels = 3;
  o.kind = t.kind;
  o.metadata = t.metadata;
  const size_t cells = t.values.size() / kNumBands;
  o.values.resize(cells * 3);
  GamutClip local;
  for (size_t c = 0; c < cells; ++c) {
    const float* v = &t.values[c * kNumBands];
    Rgb rgb = bands_to_linear_srgb([v](int b) { return v[b]; });
    (clip ? *clip : local).clip(rgb);
    o.values[c * 3] = static_cast<float>(rgb.r);
    o.values[c * 3 + 1] = static_cast<float>(rgb.g);
    o.values[c * 3 + 2] = static_cast<float>(rgb.b);
  }
  return o;
}

// ---- Metrics ----------------------------------------------------------------------------------

void MetricsAccumulator::add(double model, double measured) {
  if (!(model > 0) || !(measured > 0)) {
    ++excluded;
    return;
  }
  const double l = std::log(model / measured), r = (model - measured) / measured;
  sum_log2 += l * l;
  sum_rel2 += r * r;
  ++points;
}

void MetricsAccumulator::add(const MetricsAccumulator& o) {
  sum_log2 += o.sum_log2;
  sum_rel2 += o.sum_rel2;
  points += o.points;
  excluded += o.excluded;
}

CurveMetrics MetricsAccumulator::result() const {
  CurveMetrics m;
  m.points = points;
  m.excluded = excluded;
  if (points) {
    m.rms_log = std::sqrt(sum_log2 / static_cast<double>(points));
    m.rms_rel = std::sqrt(sum_rel2 / static_cast<double>(points));
  } else {
    m.rms_log = m.rms_rel = std::numeric_limits<double>::quiet_NaN();
  }
  return m;
}

Rgb paper_normalization(const Rgb& model, const Rgb& measured, const std::string& name) {
  Rgb f;
  for (int k = 0; k < 3; ++k) {
    if (!(model[k] > 0))
      throw Error(name, "normalization",
                  "the model's beta at normal incidence and view is not positive in channel " +
                      std::to_string(k) + ": no normalization factor exists");
    f[k] = measured[k] / model[k];
  }
  return f;
}

// ---- Colour -----------------------------------------------------------------------------------

ColourEntry colour_of_spectrum(const std::string& name, const Spectrum& s,
                               const std::string& note) {
  ColourEntry e;
  e.name = name;
  e.spectrum = s;
  e.note = note;
  e.linear_srgb = xyz_to_linear_srgb(reflectance_to_xyz_d65(s));
  Rgb c = e.linear_srgb;
  GamutClip().clip(c);
  e.hsv = rgb_to_hsv(c);
  return e;
}

FabricSpectra normal_incidence_spectra(const TabulatedBsdfTable& t) {
  if (t.channels != kNumBands)
    throw Error("", "channels", "the colour table needs a spectral (33-band) fabric table");
  const auto a = t.directional_albedo(t.grid().bin_of({0, 0, 1}));
  FabricSpectra s;
  for (int b = 0; b < kNumBands; ++b) {
    s.reflectance[b] = a.reflectance[b];
    s.transmittance[b] = a.transmittance[b];
  }
  return s;
}

// ---- Settings ---------------------------------------------------------------------------------

VerifyQuality parse_verify_quality(const std::string& name) {
  if (name == "draft") return VerifyQuality::kDraft;
  if (name == "default") return VerifyQuality::kDefault;
  if (name == "publication") return VerifyQuality::kPublication;
  throw Error("", "--quality", "'" + name + "' is not draft, default or publication");
}

std::string quality_name(VerifyQuality q) {
  return q == VerifyQuality::kDraft     ? "draft"
         : q == VerifyQuality::kDefault ? "default"
                                        : "publication";
}

VerifySettings verify_settings(VerifyQuality q) {
  VerifySettings s;
  s.quality = q;
  switch (q) {
    case VerifyQuality::kDraft:
      s.resolution = 6;
      s.fiber_photons_per_band = 20000;
      s.particles_per_bin = 4000;
      s.batches = 2;
      s.summation_samples = 4;
      s.render_size = 64;
      s.render_spp = 2;
      s.weave_render_size = 128;
      s.weave_render_spp = 4;
      break;
    case VerifyQuality::kDefault:
      s.resolution = 8;
      s.fiber_photons_per_band = 200000;  // FiberTableBakeOptions{}'s
      s.particles_per_bin = 64000;
      s.batches = 4;
      s.summation_samples = 8;
      s.render_size = 128;
      s.render_spp = 4;
      s.weave_render_size = 256;
      s.weave_render_spp = 16;
      break;
    case VerifyQuality::kPublication:
      s.resolution = 12;
      s.fiber_photons_per_band = 1000000;
      s.particles_per_bin = 256000;
      s.batches = 8;
      s.summation_samples = 16;
      s.render_size = 384;
      s.render_spp = 64;
      s.weave_render_size = 512;
      s.weave_render_spp = 32;
      break;
  }
  return s;
}

// ---- The run ----------------------------------------------------------------------------------

namespace {

// Ray-traced fabric table of 'fiber' in 'batches' independent runs: the curves of their mean and
// the standard error of that mean from their spread (what the error bars show).
struct TracedCurves {
  std::vector<std::vector<Rgb>> beta, err;
  TabulatedBsdfTable mean;  // the fiber table's channels
  double relative_noise = 0;
  bool cancelled = false;
};

FabricRaytraceOptions trace_options(const VerifySettings& s, const std::string& model, int k) {
  FabricRaytraceOptions o;
  o.resolution = s.resolution;
  o.particles_per_bin = s.particles_per_bin / static_cast<uint64_t>(s.batches);
  o.seed = batch_seed(s.seed, model, k);
  o.threads = s.threads;
  return o;
}

TracedCurves trace_curves(const WovenSample& sample, const TabulatedBsdfTable& fiber,
                          const MeasuredInplane& measured, const VerifySettings& s,
                          const std::string& model, const ProgressCallback& progress,
                          const VerifyTraced* traced) {
  TracedCurves out;
  const size_t n_inc = measured.curves.size();
  std::vector<std::vector<std::vector<Rgb>>> per_batch;  // [batch][incidence][view]
  std::vector<double> sum;
  double noise2 = 0;
  for (int k = 0; k < s.batches; ++k) {
    FabricRaytraceResult here;
    const FabricRaytraceResult* found = nullptr;
    if (traced)
      if (const auto it = traced->find({model, k}); it != traced->end()) found = &it->second;
    if (!found) {
      here = raytrace_fabric_table(sample, fiber, trace_options(s, model, k), progress);
      found = &here;
    }
    const FabricRaytraceResult& r = *found;
    if (r.table.channels != fiber.channels || r.table.resolution != s.resolution)
      throw Error("", model, "a ray trace handed in is of another table");
    if (r.cancelled) {
      out.cancelled = true;
      return out;
    }
    noise2 += r.relative_noise * r.relative_noise;
    if (sum.empty()) {
      sum.assign(r.table.values.size(), 0.0);
      out.mean = r.table;
    }
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += r.table.values[i];
    const TabulatedBsdfTable rgb = table_to_rgb(r.table);
    auto& curves = per_batch.emplace_back();
    for (const auto& c : measured.curves)
      curves.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, s.azimuths));
  }
  for (size_t i = 0; i < sum.size(); ++i)
    out.mean.values[i] = static_cast<float>(sum[i] / s.batches);
  // Each batch's noise is sqrt(batches) times the mean's.
  out.relative_noise = std::sqrt(noise2 / s.batches) / std::sqrt(double(s.batches));
  out.beta.resize(n_inc);
  out.err.resize(n_inc);
  const double kb = s.batches;
  for (size_t i = 0; i < n_inc; ++i) {
    const size_t nv = measured.curves[i].view_deg.size();
    out.beta[i].assign(nv, Rgb());
    out.err[i].assign(nv, Rgb());
    for (size_t v = 0; v < nv; ++v) {
      Rgb m, m2;
      for (const auto& b : per_batch) {
        m += b[i][v];
        m2 += b[i][v] * b[i][v];
      }
      m = m / kb;
      Rgb var = m2 / kb + m * m * -1.0;  // population variance of the batches
      Rgb err;
      for (int c = 0; c < 3; ++c) {
        const double sd2 = std::max(0.0, var[c]) * kb / std::max(1.0, kb - 1);
        (c == 0 ? err.r : c == 1 ? err.g : err.b) = std::sqrt(sd2 / kb);
      }
      out.beta[i][v] = m;
      out.err[i][v] = err;
    }
  }
  return out;
}

ModelCurves model_curves(std::string key, std::string label, std::vector<std::vector<Rgb>> beta,
                         std::vector<std::vector<Rgb>> err) {
  ModelCurves m;
  m.key = std::move(key);
  m.label = std::move(label);
  m.beta = std::move(beta);
  m.beta_err = std::move(err);
  return m;
}

void score(ModelCurves& m, const MeasuredInplane& meas, const MeasuredCurve& normal_curve,
           size_t normal_view) {
  const Rgb model0 = m.beta[&normal_curve - meas.curves.data()][normal_view];
  m.normalization = paper_normalization(model0, normal_curve.beta[normal_view], m.label);
  MetricsAccumulator abs_all, norm_all;
  for (size_t i = 0; i < meas.curves.size(); ++i) {
    MetricsAccumulator a, n;
    std::array<MetricsAccumulator, 3> ac, nc;
    const auto& c = meas.curves[i];
    for (size_t v = 0; v < c.view_deg.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        ac[k].add(m.beta[i][v][k], c.beta[v][k]);
        nc[k].add(m.beta[i][v][k] * m.normalization[k], c.beta[v][k]);
      }
    auto& acm = m.absolute_channel.emplace_back();
    auto& ncm = m.normalized_channel.emplace_back();
    for (int k = 0; k < 3; ++k) {
      a.add(ac[k]);
      n.add(nc[k]);
      acm[k] = ac[k].result();
      ncm[k] = nc[k].result();
    }
    m.absolute.push_back(a.result());
    m.normalized.push_back(n.result());
    abs_all.add(a);
    norm_all.add(n);
  }
  m.absolute_overall = abs_all.result();
  m.normalized_overall = norm_all.result();
}

}  // namespace

std::vector<VerifyTrace> verify_traces(const VerifySettings& s) {
  std::vector<VerifyTrace> out;
  for (const char* model : {"computed", "classic"})
    for (int k = 0; k < s.batches; ++k) out.push_back({model, k, trace_options(s, model, k)});
  return out;
}

ClassicFiber verify_classic_fiber(const VerifyInputs& in, const VerifySettings& s,
                                  const ProgressCallback& progress) {
  ClassicFiber c;
  // The fiber's volume albedo as a reflectance: components outside [0, 1] are removed (and
  // reported).
  Rgb refl = bands_to_linear_srgb([&](int b) { return in.volume_albedo[b]; });
  c.clip.clip(refl);
  for (double* v : {&refl.r, &refl.g, &refl.b})
    if (*v > 1) {
      c.clip.largest = std::max(c.clip.largest, *v - 1);
      ++c.clip.components;
      *v = 1;
    }
  if (in.classic_diffuse) {
    const Rgb d = *in.classic_diffuse;
    for (int k = 0; k < 3; ++k)
      if (!(d[k] >= 0 && d[k] <= 1))
        throw Error("", "classic_diffuse", "a reflectance lies in [0, 1]");
    refl = d;
    c.clip = GamutClip();
  }
  c.reflectance = refl;
  c.table = classic_fiber_table(refl, in.classic_distribution, in.classic_ior, s.resolution,
                                s.summation_samples, s.seed, s.threads, progress);
  return c;
}

VerifyReport run_verify(const WovenSample& sample, const VerifyInputs& in,
                        const MeasuredInplane& measured, const VerifySettings& s,
                        const ProgressCallback& progress, const VerifyTraced* traced) {
  if (s.batches < 2) throw Error("", "batches", "the error bars need at least 2 batches");
  if (s.particles_per_bin < static_cast<uint64_t>(s.batches))
    throw Error("", "particles_per_bin", "fewer particles than batches");
  if (in.fiber.resolution != s.resolution)
    throw Error("", "fiber.resolution", "the fiber table's resolution differs from the settings'");
  // The paper's normalization needs the measurement at normal incidence and view.
  const MeasuredCurve* normal_curve = nullptr;
  size_t normal_view = 0;
  for (const auto& c : measured.curves)
    if (c.theta_i_deg == 0)
      for (size_t v = 0; v < c.view_deg.size(); ++v)
        if (c.view_deg[v] == 0) {
          normal_curve = &c;
          normal_view = v;
        }
  if (!normal_curve)
    throw Error(measured.file, "theta_i_deg",
                "no row at theta_i_deg = 0, theta_o_deg = 0 (the paper's normalization needs it)");

  VerifyReport rep;
  rep.settings = s;
  rep.measured = measured;
  rep.seconds = in.seconds;
  rep.fiber_name = in.fiber_name;
  rep.sample_name = in.sample_name;
  const auto t_all = std::chrono::steady_clock::now();

  // Computed: the fiber-level ray trace of the fiber table.
  auto t0 = std::chrono::steady_clock::now();
  TracedCurves computed = trace_curves(sample, in.fiber, measured, s, "computed", progress, traced);
  if (computed.cancelled) {
    rep.cancelled = true;
    return rep;
  }
  rep.seconds["raytrace_computed"] = seconds_since(t0);
  rep.raytrace_relative_noise = computed.relative_noise;
  {
    GamutClip clip;
    table_to_rgb(computed.mean, &clip);
    rep.fabric_table_gamut_clipped = clip.components;
  }
  rep.models.push_back(model_curves("computed_raytrace", "computed (fiber-level ray trace)",
                                    computed.beta, computed.err));
  rep.computed_fabric = computed.mean;
  rep.computed_fiber = in.fiber;
  if (sample.fibers.curve_count() > 0) rep.sample = std::make_shared<const WovenSample>(sample);

  // Computed: the paper's summation (deterministic up to its stratified cell sampling).
  if (in.summation) {
    const TabulatedBsdfTable rgb = table_to_rgb(*in.summation);
    ModelCurves m = model_curves("computed_summation", "computed (paper's summation)", {}, {});
    for (const auto& c : measured.curves) {
      m.beta.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, s.azimuths));
      m.beta_err.emplace_back(c.view_deg.size(), Rgb());
    }
    rep.models.push_back(std::move(m));
  }

  // Classic: Lambert + Cook-Torrance with the fiber's volume albedo as its diffuse colour.
  t0 = std::chrono::steady_clock::now();
  const ClassicFiber classic = verify_classic_fiber(in, s, progress);
  rep.classic_clip = classic.clip;
  rep.classic_reflectance = classic.reflectance;
  rep.classic_source = in.classic_source;
  TracedCurves cl = trace_curves(sample, classic.table, measured, s, "classic", progress, traced);
  if (cl.cancelled) {
    rep.cancelled = true;
    return rep;
  }
  rep.seconds["raytrace_classic"] = seconds_since(t0);
  rep.models.push_back(
      model_curves("classic", "classic (Lambert + Cook-Torrance)", cl.beta, cl.err));
  rep.classic_fabric = std::move(cl.mean);
  rep.classic_fiber = classic.table;
  // The measured BRDF's neural fit, where the measurement has one (materials/data/measured/*/).
  {
    std::error_code ec;
    const auto net = std::filesystem::path(measured.file).parent_path() / "nbrdf_weights.txt";
    if (std::filesystem::is_regular_file(net, ec)) rep.measured_nbrdf = net;
  }

  for (auto& m : rep.models) score(m, measured, *normal_curve, normal_view);

  // Colour table (paper's Table 1): the spectral ray-traced fabric at normal incidence.
  if (computed.mean.channels == kNumBands) {
    const FabricSpectra sp = normal_incidence_spectra(computed.mean);
    rep.colours.push_back(colour_of_spectrum(
        "computed fabric, reflection", sp.reflectance,
        "directional reflectance at normal incidence (light and viewer on the same side)"));
    rep.colours.push_back(colour_of_spectrum(
        "computed fabric, transmission", sp.transmittance,
        "directional transmittance at normal incidence (light and viewer on opposite sides)"));
    if (in.summation && in.summation->channels == kNumBands) {
      const FabricSpectra ss = normal_incidence_spectra(*in.summation);
      rep.colours.push_back(colour_of_spectrum("paper's summation, reflection", ss.reflectance,
                                               "the summation transmits nothing"));
    }
    if (!in.classic_diffuse)
      rep.colours.push_back(colour_of_spectrum("fiber volume albedo (classic diffuse colour)",
                                               in.volume_albedo,
                                               "before clipping to [0, 1]; " + in.classic_source));
  }
  {
    ColourEntry paper;
    paper.name = "real fabric (paper, Table 1)";
    paper.hsv = {0.98, 0.99, 0.8};
    paper.linear_srgb = {std::nan(""), std::nan(""), std::nan("")};
    paper.note = "Voloboy et al. 2010, Table 1 (HSV only)";
    rep.colours.push_back(paper);
    ColourEntry merl;
    merl.name = "measured (this table), normal incidence and view";
    merl.linear_srgb = normal_curve->beta[normal_view];
    merl.hsv = rgb_to_hsv(merl.linear_srgb);
    merl.note = "camera RGB of the measurement's database, not sRGB: hue only roughly comparable";
    rep.colours.push_back(merl);
  }
  rep.seconds["verify_library"] = seconds_since(t_all);
  return rep;
}

// ---- Fitting ----------------------------------------------------------------------------------

std::vector<double> classic_diffuse_from_fiber_table(const TabulatedBsdfTable& fiber,
                                                     const MicrofacetDistribution& d, double ior,
                                                     uint64_t seed, int threads) {
  // The lobe at a fixed fine resolution, not the table's: at R = 3 with 4 samples per cell pair
  // the tabulated lobe loses a fifth of its albedo (0.0587 for Beckmann 0.35, n 1.557); at R = 16
  // it is within 0.0002 of its value at R = 24 with 16 samples (0.0729).
  const double lobe = classic_fiber_table(Rgb(0.0), d, ior, 16, 4, seed, threads).total_albedo()[0];
  std::vector<double> out = fiber.total_albedo();
  for (double& v : out) v -= lobe;
  return out;
}

std::optional<MicrofacetDistribution> fiber_table_roughness(const TabulatedBsdfTable& t,
                                                            const std::string& file) {
  const auto it = t.metadata.find("roughness");
  if (it == t.metadata.end()) return std::nullopt;
  std::istringstream in(it->second);
  std::string model, word;
  double alpha = 0;
  if (!(in >> model >> word >> alpha) || word != "alpha" || !(in >> std::ws).eof() ||
      !(model == "beckmann" || model == "ggx") || !(alpha > 0 && alpha <= 1))
    throw Error(file, "roughness",
                "'" + it->second + "' is not '<beckmann|ggx> alpha A' with A in (0, 1]");
  return MicrofacetDistribution{
      model == "beckmann" ? MicrofacetModel::kBeckmann : MicrofacetModel::kGgx, alpha};
}

std::vector<std::vector<Rgb>> table_curves(const TabulatedBsdfTable& table,
                                           const MeasuredInplane& measured, int azimuths) {
  const TabulatedBsdfTable rgb = table_to_rgb(table);
  std::vector<std::vector<Rgb>> out;
  for (const auto& c : measured.curves)
    out.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, azimuths));
  return out;
}

FitInner parse_fit_inner(const std::string& name) {
  if (name == "raytrace") return FitInner::kRaytrace;
  if (name == "summation") return FitInner::kSummation;
  throw Error("", "--fit-inner", "'" + name + "' is not raytrace or summation");
}

std::string fit_inner_name(FitInner inner) {
  return inner == FitInner::kRaytrace ? "raytrace" : "summation";
}

FitInnerSettings fit_inner_settings(const VerifySettings& s) {
  FitInnerSettings f;
  f.seed = s.seed;
  f.azimuths = s.azimuths;
  f.threads = s.threads;
  return f;
}

void FitOptions::validate(size_t parameters) const {
  const int least = 2 * static_cast<int>(parameters) + 2;
  if (max_evaluations < least)
    throw Error("", "--fit-evaluations",
                std::to_string(max_evaluations) + " is fewer than 2 p + 2 = " +
                    std::to_string(least) + " (the simplex and a first step)");
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    throw Error("", "tolerance", "must be a positive number");
  if (!(initial_step > 0 && initial_step <= 0.5))
    throw Error("", "initial_step", "must lie in (0, 0.5]");
  if (!(jacobian_step > 0 && jacobian_step <= 0.25))
    throw Error("", "jacobian_step", "must lie in (0, 0.25]");
}

std::vector<double> fit_residuals(const std::vector<std::vector<Rgb>>& model,
                                  const MeasuredInplane& measured) {
  if (model.size() != measured.curves.size())
    throw Error(measured.file, "fit", "the model's incidences differ from the measurement's");
  std::vector<double> r;
  for (size_t i = 0; i < model.size(); ++i) {
    const auto& c = measured.curves[i];
    if (model[i].size() != c.view_deg.size())
      throw Error(measured.file, "fit", "the model's views differ from the measurement's");
    for (size_t v = 0; v < c.view_deg.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        const double m = c.beta[v][k], x = model[i][v][k];
        if (!(m > 0)) continue;
        r.push_back(x > 0 ? std::log(x / m) : std::log(1e-6));
      }
  }
  return r;
}

namespace {

double sum_squares(const std::vector<double>& r) {
  double s = 0;
  for (double x : r) s += x * x;
  return s;
}

double rms(const std::vector<double>& r) {
  return r.empty() ? 0.0 : std::sqrt(sum_squares(r) / static_cast<double>(r.size()));
}

// Unit-cube coordinate <-> the parameter's own value.
double to_value(const FitParameter& p, double u) {
  return p.log_scale ? std::exp(std::log(p.lo) + u * (std::log(p.hi) - std::log(p.lo)))
                     : p.lo + u * (p.hi - p.lo);
}

CurveMetrics absolute_metrics(const std::vector<std::vector<Rgb>>& model,
                              const MeasuredInplane& measured) {
  MetricsAccumulator a;
  for (size_t i = 0; i < model.size(); ++i)
    for (size_t v = 0; v < model[i].size(); ++v)
      for (int k = 0; k < 3; ++k)
        a.add(model[i][v][k], measured.curves[i].beta[v][k]);
  return a.result();
}

// Inverse of a small symmetric matrix by Gauss-Jordan with partial pivoting; false if singular.
bool invert(std::vector<std::vector<double>>& a) {
  const size_t n = a.size();
  std::vector<std::vector<double>> inv(n, std::vector<double>(n, 0.0));
  for (size_t i = 0; i < n; ++i) inv[i][i] = 1;
  double scale = 0;
  for (const auto& row : a)
    for (double x : row) scale = std::max(scale, std::abs(x));
  for (size_t c = 0; c < n; ++c) {
    size_t piv = c;
    for (size_t r = c + 1; r < n; ++r)
      if (std::abs(a[r][c]) > std::abs(a[piv][c])) piv = r;
    if (!(std::abs(a[piv][c]) > 1e-12 * scale)) return false;
    std::swap(a[piv], a[c]);
    std::swap(inv[piv], inv[c]);
    const double d = a[c][c];
    for (size_t k = 0; k < n; ++k) {
      a[c][k] /= d;
      inv[c][k] /= d;
    }
    for (size_t r = 0; r < n; ++r) {
      if (r == c) continue;
      const double f = a[r][c];
      for (size_t k = 0; k < n; ++k) {
        a[r][k] -= f * a[c][k];
        inv[r][k] -= f * inv[c][k];
      }
    }
  }
  a = inv;
  return true;
}

// A search's outcome in the unit cube.
struct FitSearch {
  std::vector<double> u;
  double objective_start = 0, objective = 0;
  bool converged = false;
};

using ResidualsAt = std::function<std::vector<double>(const std::vector<double>&)>;

std::vector<double> clamped(std::vector<double> u) {
  for (double& x : u) x = std::clamp(x, 0.0, 1.0);
  return u;
}

// Nelder-Mead (standard coefficients 1, 2, 0.5, 0.5) on the RMS of the residuals in the unit
// cube; points are projected into the cube, so every evaluation is a valid parameter set.
// 'at_start' runs right after the start's evaluation.
FitSearch nelder_mead(const ResidualsAt& residuals_at, const std::vector<double>& u0,
                      const FitOptions& o, const std::function<void()>& at_start) {
  const size_t n = u0.size();
  int evaluations = 0;
  auto objective = [&](const std::vector<double>& u) {
    ++evaluations;
    return rms(residuals_at(u));
  };
  FitSearch out;
  std::vector<std::vector<double>> simplex{u0};
  for (size_t k = 0; k < n; ++k) {
    auto u = u0;
    u[k] += u[k] + o.initial_step <= 1 ? o.initial_step : -o.initial_step;
    simplex.push_back(u);
  }
  std::vector<double> f;
  for (const auto& u : simplex) {
    f.push_back(objective(u));
    if (f.size() == 1) at_start();
  }
  out.objective_start = f[0];
  while (evaluations < o.max_evaluations) {
    std::vector<size_t> order(n + 1);
    for (size_t k = 0; k <= n; ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return f[a] < f[b]; });
    std::vector<std::vector<double>> s2;
    std::vector<double> f2;
    for (size_t k : order) {
      s2.push_back(simplex[k]);
      f2.push_back(f[k]);
    }
    simplex = std::move(s2);
    f = std::move(f2);
    double size = 0;
    for (size_t k = 1; k <= n; ++k)
      for (size_t d = 0; d < n; ++d) size = std::max(size, std::abs(simplex[k][d] - simplex[0][d]));
    if (f[n] - f[0] < o.tolerance && size < 1e-3) {
      out.converged = true;
      break;
    }
    std::vector<double> centroid(n, 0.0);
    for (size_t k = 0; k < n; ++k)
      for (size_t d = 0; d < n; ++d) centroid[d] += simplex[k][d] / static_cast<double>(n);
    auto along = [&](double t) {
      std::vector<double> u(n);
      for (size_t d = 0; d < n; ++d) u[d] = centroid[d] + t * (simplex[n][d] - centroid[d]);
      return clamped(u);
    };
    const auto ur = along(-1.0);
    const double fr = objective(ur);
    if (fr < f[0]) {
      const auto ue = along(-2.0);
      const double fe = objective(ue);
      if (fe < fr) {
        simplex[n] = ue;
        f[n] = fe;
      } else {
        simplex[n] = ur;
        f[n] = fr;
      }
    } else if (fr < f[n - 1]) {
      simplex[n] = ur;
      f[n] = fr;
    } else {
      const bool outside = fr < f[n];
      const auto uc = along(outside ? -0.5 : 0.5);
      const double fc = objective(uc);
      if (fc < (outside ? fr : f[n])) {
        simplex[n] = uc;
        f[n] = fc;
      } else {  // shrink towards the best point
        for (size_t k = 1; k <= n; ++k) {
          for (size_t d = 0; d < n; ++d)
            simplex[k][d] = simplex[0][d] + 0.5 * (simplex[k][d] - simplex[0][d]);
          f[k] = objective(simplex[k]);
        }
      }
    }
  }
  size_t best = 0;
  for (size_t k = 1; k <= n; ++k)
    if (f[k] < f[best]) best = k;
  out.u = simplex[best];
  out.objective = f[best];
  return out;
}

// Levenberg-Marquardt on the residuals in the unit cube (Marquardt's scaling by diag(J^T J),
// Nielsen's update of the damping). The Jacobian is by one-sided differences towards the cube's
// inside (n evaluations); a step is projected into the cube, and a parameter at its bound whose
// gradient points outside is held there. Converged when an accepted step lowers the RMS by less
// than the tolerance and the step's linear model predicted no more, or when no step of more than
// 1e-3 of a box is left to try (the damping has shrunk it to nothing: no descent at this scale).
FitSearch levenberg_marquardt(const ResidualsAt& residuals_at, const std::vector<double>& u0,
                              const FitOptions& o, const std::function<void()>& at_start) {
  const size_t n = u0.size();
  int evaluations = 0;
  auto eval = [&](const std::vector<double>& u) {
    ++evaluations;
    return residuals_at(u);
  };
  FitSearch out;
  out.u = u0;
  std::vector<double> r = eval(u0);
  at_start();
  const size_t m = r.size();
  const double count = static_cast<double>(std::max<size_t>(m, 1));
  double ssr = sum_squares(r);
  out.objective_start = std::sqrt(ssr / count);
  double lambda = -1, nu = 2;
  while (evaluations + static_cast<int>(n) + 1 <= o.max_evaluations) {
    std::vector<std::vector<double>> jac(n, std::vector<double>(m));
    for (size_t k = 0; k < n; ++k) {
      auto up = out.u;
      const double h = out.u[k] + o.jacobian_step <= 1 ? o.jacobian_step : -o.jacobian_step;
      up[k] += h;
      const std::vector<double> rp = eval(up);
      for (size_t i = 0; i < m; ++i) jac[k][i] = (rp[i] - r[i]) / h;
    }
    std::vector<std::vector<double>> a(n, std::vector<double>(n, 0.0));
    std::vector<double> g(n, 0.0);  // J^T r: half the gradient of the SSR
    for (size_t p = 0; p < n; ++p) {
      for (size_t i = 0; i < m; ++i) g[p] += jac[p][i] * r[i];
      for (size_t q = 0; q < n; ++q)
        for (size_t i = 0; i < m; ++i) a[p][q] += jac[p][i] * jac[q][i];
    }
    double diag_max = 0;
    for (size_t k = 0; k < n; ++k) diag_max = std::max(diag_max, a[k][k]);
    if (!(diag_max > 0)) {  // the residuals do not move: nothing to descend
      out.converged = true;
      break;
    }
    if (lambda < 0) lambda = 1e-3 * diag_max;
    bool stepped = false, stop = false;
    while (!stepped && !stop) {
      std::vector<size_t> free;
      for (size_t k = 0; k < n; ++k)
        if (!((out.u[k] <= 0 && g[k] > 0) || (out.u[k] >= 1 && g[k] < 0))) free.push_back(k);
      std::vector<double> s(n, 0.0);
      bool solved = !free.empty();
      if (solved) {
        std::vector<std::vector<double>> b(free.size(), std::vector<double>(free.size()));
        for (size_t p = 0; p < free.size(); ++p)
          for (size_t q = 0; q < free.size(); ++q)
            b[p][q] = a[free[p]][free[q]] +
                      (p == q ? lambda * std::max(a[free[p]][free[p]], 1e-9 * diag_max) : 0.0);
        solved = invert(b);
        if (solved) {
          std::vector<double> un = out.u;
          for (size_t p = 0; p < free.size(); ++p) {
            double d = 0;
            for (size_t q = 0; q < free.size(); ++q) d -= b[p][q] * g[free[q]];
            un[free[p]] += d;
          }
          un = clamped(un);
          for (size_t k = 0; k < n; ++k) s[k] = un[k] - out.u[k];
        }
      }
      double longest = 0;
      for (double x : s) longest = std::max(longest, std::abs(x));
      if (!solved || longest < 1e-3) {
        out.converged = true;
        stop = true;
        break;
      }
      if (evaluations + 1 > o.max_evaluations) {
        stop = true;
        break;
      }
      // The linear model's decrease of the SSR along the (projected) step: -(2 g.s + s.A s).
      double predicted = 0;
      for (size_t p = 0; p < n; ++p) {
        predicted -= 2 * g[p] * s[p];
        for (size_t q = 0; q < n; ++q) predicted -= s[p] * a[p][q] * s[q];
      }
      std::vector<double> un = out.u;
      for (size_t k = 0; k < n; ++k) un[k] += s[k];
      std::vector<double> rn = eval(un);
      const double ssr_new = sum_squares(rn);
      if (ssr_new < ssr) {
        const double rho = predicted > 0 ? (ssr - ssr_new) / predicted : 0.0;
        const double drop = std::sqrt(ssr / count) - std::sqrt(ssr_new / count);
        const double drop_predicted =
            std::sqrt(ssr / count) - std::sqrt(std::max(0.0, ssr - predicted) / count);
        out.u = un;
        r = std::move(rn);
        ssr = ssr_new;
        lambda *= std::max(1.0 / 3.0, 1 - std::pow(2 * rho - 1, 3));
        nu = 2;
        stepped = true;
        if (drop < o.tolerance && drop_predicted < o.tolerance) {
          out.converged = true;
          stop = true;
        }
      } else {
        lambda *= nu;
        nu *= 2;
      }
    }
    if (stop) break;
  }
  out.objective = std::sqrt(ssr / count);
  return out;
}

}  // namespace

FitMethod parse_fit_method(const std::string& name) {
  if (name == "lm") return FitMethod::kLevenbergMarquardt;
  if (name == "nelder-mead") return FitMethod::kNelderMead;
  throw Error("", "--fit-method", "'" + name + "' is not lm or nelder-mead");
}

std::string fit_method_name(FitMethod method) {
  return method == FitMethod::kNelderMead ? "nelder-mead" : "lm";
}

double fit_unit(const FitParameter& p, double x) {
  return p.log_scale ? (std::log(x) - std::log(p.lo)) / (std::log(p.hi) - std::log(p.lo))
                     : (x - p.lo) / (p.hi - p.lo);
}

FitResult fit_inplane(const std::string& model, const std::vector<FitParameter>& params,
                      const InplaneModel& inplane, const MeasuredInplane& measured,
                      const FitOptions& o) {
  if (params.empty() || params.size() > 4)
    throw Error("", "--fit-params",
                "fit between one and four parameters (the same budget for both models), not " +
                    std::to_string(params.size()));
  for (const auto& p : params) {
    if (!(p.lo < p.hi) || !std::isfinite(p.lo) || !std::isfinite(p.hi) ||
        (p.log_scale && !(p.lo > 0)))
      throw Error("", p.name, "the fit's box must have lo < hi (and lo > 0 on a log scale)");
    if (!(p.start >= p.lo && p.start <= p.hi))
      throw Error("", p.name,
                  "the start " + fmt(p.start, 6) + " lies outside [" + fmt(p.lo, 6) + ", " +
                      fmt(p.hi, 6) + "]");
  }
  o.validate(params.size());
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = params.size();
  FitResult res;
  res.model = model;
  auto values_of = [&](const std::vector<double>& u) {
    std::vector<double> x(n);
    for (size_t k = 0; k < n; ++k) x[k] = to_value(params[k], std::clamp(u[k], 0.0, 1.0));
    return x;
  };
  std::vector<std::vector<Rgb>> last;  // the latest evaluation's curves (for the metrics)
  auto residuals_at = [&](const std::vector<double>& u) {
    ++res.evaluations;
    last = inplane(values_of(u));
    return fit_residuals(last, measured);
  };
  std::vector<double> u0(n);
  for (size_t k = 0; k < n; ++k) u0[k] = fit_unit(params[k], params[k].start);
  const std::function<void()> at_start = [&] {
    res.start_metrics = absolute_metrics(last, measured);
  };
  const FitSearch search = o.method == FitMethod::kNelderMead
                               ? nelder_mead(residuals_at, u0, o, at_start)
                               : levenberg_marquardt(residuals_at, u0, o, at_start);
  res.method = fit_method_name(o.method);
  res.objective_start = search.objective_start;
  res.objective = search.objective;
  res.converged = search.converged;
  for (size_t k = 0; k < n; ++k) {
    FitParameterResult p;
    p.parameter = params[k];
    p.value = to_value(params[k], search.u[k]);
    p.at_bound = search.u[k] < 1e-3 || search.u[k] > 1 - 1e-3;
    p.sigma = std::nan("");
    res.parameters.push_back(p);
  }
  res.seconds = seconds_since(t0);
  if (o.uncertainty) add_fit_uncertainty(res, inplane, measured, o);
  return res;
}

void add_fit_uncertainty(FitResult& res, const InplaneModel& inplane,
                         const MeasuredInplane& measured, const FitOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = res.parameters.size();
  std::vector<double> ub(n);
  for (size_t k = 0; k < n; ++k)
    ub[k] = std::clamp(fit_unit(res.parameters[k].parameter, res.parameters[k].value), 0.0, 1.0);
  std::vector<std::vector<Rgb>> last;
  auto residuals_at = [&](const std::vector<double>& u) {
    ++res.evaluations;
    std::vector<double> x(n);
    for (size_t k = 0; k < n; ++k) x[k] = to_value(res.parameters[k].parameter, u[k]);
    last = inplane(x);
    return fit_residuals(last, measured);
  };
  const std::vector<double> r0 = residuals_at(ub);
  res.fitted_metrics = absolute_metrics(last, measured);

  // J by central differences in u (one-sided at a bound), s^2 = SSR / (m - p).
  const size_t m = r0.size();
  std::vector<std::vector<double>> jac(n);
  for (size_t k = 0; k < n; ++k) {
    auto up = ub, dn = ub;
    up[k] = std::min(1.0, ub[k] + o.jacobian_step);
    dn[k] = std::max(0.0, ub[k] - o.jacobian_step);
    const auto rp = residuals_at(up), rm = residuals_at(dn);
    jac[k].resize(m);
    for (size_t i = 0; i < m; ++i) jac[k][i] = (rp[i] - rm[i]) / (up[k] - dn[k]);
  }
  std::vector<std::vector<double>> jtj(n, std::vector<double>(n, 0.0));
  for (size_t a = 0; a < n; ++a)
    for (size_t b = 0; b < n; ++b)
      for (size_t i = 0; i < m; ++i) jtj[a][b] += jac[a][i] * jac[b][i];
  const double ssr = sum_squares(r0);
  const double s2 = m > n ? ssr / static_cast<double>(m - n) : std::nan("");
  const bool ok = invert(jtj);
  for (size_t k = 0; k < n; ++k) {
    FitParameterResult& p = res.parameters[k];
    // d value / d u converts the unit-cube standard deviation to the parameter's own units.
    const double dxdu = p.parameter.log_scale
                            ? p.value * (std::log(p.parameter.hi) - std::log(p.parameter.lo))
                            : p.parameter.hi - p.parameter.lo;
    p.sigma = ok && jtj[k][k] > 0 ? dxdu * std::sqrt(s2 * jtj[k][k]) : std::nan("");
  }
  res.seconds += seconds_since(t0);
}

// ---- Report files ---------------------------------------------------------------------------

std::string verify_inplane_csv(const VerifyReport& r) {
  std::ostringstream o;
  o.precision(9);
  o << "theta_i_deg,view_zenith_deg,model,channel,beta,beta_err,beta_norm,norm_factor\n";
  const char* ch[3] = {"R", "G", "B"};
  for (size_t i = 0; i < r.measured.curves.size(); ++i) {
    const auto& c = r.measured.curves[i];
    for (size_t v = 0; v < c.view_deg.size(); ++v) {
      for (int k = 0; k < 3; ++k)
        o << c.theta_i_deg << ',' << c.view_deg[v] << ",measured," << ch[k] << ','
          << c.beta[v][k] << ",0," << c.beta[v][k] << ",1\n";
      for (const auto& m : r.models)
        for (int k = 0; k < 3; ++k) {
          const double f = m.normalization[k];
          o << c.theta_i_deg << ',' << c.view_deg[v] << ',' << m.key << ',' << ch[k] << ','
            << m.beta[i][v][k] << ',' << m.beta_err[i][v][k] << ','
            << m.beta[i][v][k] * f << ',' << f << '\n';
        }
    }
  }
  return o.str();
}

std::string verify_metrics_json(const VerifyReport& r) {
  nlohmann::json j;
  j["report"] = "weft verify";
  j["measured"] = r.measured.file;
  j["fiber"] = r.fiber_name;
  j["sample"] = r.sample_name;
  const VerifySettings& s = r.settings;
  j["settings"] = {{"quality", quality_name(s.quality)},
                   {"resolution", s.resolution},
                   {"fiber_photons_per_band", s.fiber_photons_per_band},
                   {"particles_per_bin", s.particles_per_bin},
                   {"batches", s.batches},
                   {"summation_samples", s.summation_samples},
                   {"azimuths", s.azimuths},
                   {"render_size", s.render_size},
                   {"render_spp", s.render_spp},
                   {"weave_render_size", s.weave_render_size},
                   {"weave_render_spp", s.weave_render_spp},
                   {"threads", s.threads}};
  j["seed"] = s.seed;
  j["seconds"] = r.seconds;
  j["normalization"] =
      "paper (section 4): per model and channel, beta scaled so that beta at normal incidence and "
      "view equals the measured one";
  j["metrics"] =
      "rms_log: RMS of ln(model / measured); rms_rel: RMS of (model - measured) / "
      "measured; over every view, incidence and channel where both are positive";
  nlohmann::json models = nlohmann::json::object();
  for (const auto& m : r.models) {
    nlohmann::json per = nlohmann::json::array();
    for (size_t i = 0; i < r.measured.curves.size(); ++i) {
      nlohmann::json channels = nlohmann::json::object();
      if (i < m.absolute_channel.size())
        for (int k = 0; k < 3; ++k)
          channels[std::string(1, "RGB"[k])] = {
              {"absolute", metrics_json(m.absolute_channel[i][k])},
              {"normalized", metrics_json(m.normalized_channel[i][k])}};
      per.push_back({{"theta_i_deg", r.measured.curves[i].theta_i_deg},
                     {"absolute", metrics_json(m.absolute[i])},
                     {"normalized", metrics_json(m.normalized[i])},
                     {"channels", channels}});
    }
    models[m.key] = {{"label", m.label},
                     {"normalization_factor", rgb_json(m.normalization)},
                     {"absolute", metrics_json(m.absolute_overall)},
                     {"normalized", metrics_json(m.normalized_overall)},
                     {"per_incidence", per}};
  }
  j["models"] = models;
  // The headline figures: computed is the fiber-level ray trace.
  for (const auto& m : r.models) {
    if (m.key == "computed_raytrace") {
      j["computed_rms_log"] = m.normalized_overall.rms_log;
      j["computed_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["computed_rms_rel"] = m.normalized_overall.rms_rel;
      j["computed_rms_rel_absolute"] = m.absolute_overall.rms_rel;
    }
    if (m.key == "computed_raytrace_fitted") {
      j["computed_fitted_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["computed_fitted_rms_log"] = m.normalized_overall.rms_log;
    }
    if (m.key == "classic_fitted") {
      j["classic_fitted_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["classic_fitted_rms_log"] = m.normalized_overall.rms_log;
    }
    if (m.key == "classic") {
      j["classic_rms_log"] = m.normalized_overall.rms_log;
      j["classic_rms_log_absolute"] = m.absolute_overall.rms_log;
      j["classic_rms_rel"] = m.normalized_overall.rms_rel;
      j["classic_rms_rel_absolute"] = m.absolute_overall.rms_rel;
    }
  }
  if (!r.fits.empty()) {
    nlohmann::json fit = nlohmann::json::object();
    for (const auto& f : r.fits) {
      nlohmann::json ps = nlohmann::json::array();
      for (const auto& p : f.parameters)
        ps.push_back(
            {{"name", p.parameter.name},
             {"unit", p.parameter.unit},
             {"start", p.parameter.start},
             {"lo", p.parameter.lo},
             {"hi", p.parameter.hi},
             {"log_scale", p.parameter.log_scale},
             {"value", p.value},
             {"sigma", std::isfinite(p.sigma) ? nlohmann::json(p.sigma) : nlohmann::json()},
             {"sigma_restarts", std::isfinite(p.sigma_restarts) ? nlohmann::json(p.sigma_restarts)
                                                                : nlohmann::json()},
             {"at_bound", p.at_bound}});
      nlohmann::json e = {{"parameters", ps},
                          {"inner_model", f.inner_model},
                          {"method", f.method},
                          {"uncertainty", f.uncertainty},
                          {"objective", "rms_log, absolute, of the inner model"},
                          {"inner_rms_log_start", f.objective_start},
                          {"inner_rms_log_fitted", f.objective},
                          {"inner_start", metrics_json(f.start_metrics)},
                          {"inner_fitted", metrics_json(f.fitted_metrics)},
                          {"evaluations", f.evaluations},
                          {"converged", f.converged},
                          {"seconds", f.seconds}};
      // The fitted parameters at the run's quality (the same ray trace as the unfitted curves).
      const std::string key =
          f.model == "computed" ? "computed_raytrace_fitted" : f.model + "_fitted";
      for (const auto& m : r.models)
        if (m.key == key)
          e["at_run_quality"] = {{"model", key},
                                 {"absolute", metrics_json(m.absolute_overall)},
                                 {"normalized", metrics_json(m.normalized_overall)}};
      fit[f.model] = e;
    }
    j["fit"] = fit;
  }
  nlohmann::json colours = nlohmann::json::array();
  for (const auto& c : r.colours) {
    nlohmann::json e = {{"name", c.name}, {"hsv", {c.hsv.h, c.hsv.s, c.hsv.v}}, {"note", c.note}};
    if (std::isfinite(c.linear_srgb.r)) e["linear_srgb"] = rgb_json(c.linear_srgb);
    if (c.spectrum) e["spectrum"] = *c.spectrum;
    colours.push_back(e);
  }
  j["colour_table"] = colours;
  nlohmann::json renders = nlohmann::json::array();
  for (const auto& v : r.renders) {
    nlohmann::json e = {{"kind", v.kind},
                        {"model", v.model},
                        {"configuration", v.configuration},
                        {"exr", v.stem + ".exr"},
                        {"png", v.stem + ".png"},
                        {"caption", v.caption},
                        {"mean_linear_srgb", rgb_json(v.mean)}};
    if (v.kind == "patch") e["patch_radiance_linear_srgb"] = rgb_json(v.patch_radiance);
    renders.push_back(e);
  }
  j["renders"] = renders;
  j["render_setup"] = kVerifyRenderSetup;
  j["weave_render_setup"] = kVerifyWeaveRenderSetup;
  j["classic_reflectance_linear_srgb"] = rgb_json(r.classic_reflectance);
  j["classic_reflectance_clipped_components"] = r.classic_clip.components;
  j["classic_source"] = r.classic_source;
  j["fabric_table_gamut_clipped_components"] = r.fabric_table_gamut_clipped;
  j["raytrace_relative_noise"] = r.raytrace_relative_noise;
  return j.dump(2) + "\n";
}

std::string verify_index_html(const VerifyReport& r,
                              const std::vector<std::pair<std::string, std::string>>& images) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>weft verify</title>\n"
       "<style>body{font-family:sans-serif;max-width:1400px;margin:auto}table{border-collapse:"
       "collapse}td,th{border:1px solid #aaa;padding:3px 8px;text-align:right}"
       "td:first-child,th:first-child{text-align:left}img{max-width:100%}</style></head><body>\n";
  h << "<h1>weft verify: computed fabric vs measurement vs classic model</h1>\n";
  h << "<p>Measurement: " << html_escape(r.measured.file)
    << "<br>Fiber: " << html_escape(r.fiber_name) << "<br>Sample: " << html_escape(r.sample_name)
    << "</p>\n";
  h << "<h2>Metrics (over every view, incidence and channel)</h2>\n<table><tr><th>model</th>"
       "<th>RMS log ratio, normalized</th><th>RMS relative, normalized</th><th>RMS log ratio, "
       "absolute</th><th>RMS relative, absolute</th><th>normalization factor (R, G, B)</th>"
       "<th>points (excluded)</th></tr>\n";
  for (const auto& m : r.models)
    h << "<tr><td>" << html_escape(m.label) << "</td><td>" << fmt(m.normalized_overall.rms_log)
      << "</td><td>" << fmt(m.normalized_overall.rms_rel) << "</td><td>"
      << fmt(m.absolute_overall.rms_log) << "</td><td>" << fmt(m.absolute_overall.rms_rel)
      << "</td><td>" << fmt(m.normalization.r) << ", " << fmt(m.normalization.g) << ", "
      << fmt(m.normalization.b) << "</td><td>" << m.normalized_overall.points << " ("
      << m.normalized_overall.excluded << ")</td></tr>\n";
  h << "</table>\n<h3>Per incidence: RMS log ratio, normalized (absolute)</h3>\n<table><tr>"
       "<th>theta_i (deg)</th>";
  for (const auto& m : r.models) h << "<th>" << html_escape(m.label) << "</th>";
  h << "</tr>\n";
  for (size_t i = 0; i < r.measured.curves.size(); ++i) {
    h << "<tr><td>" << fmt(r.measured.curves[i].theta_i_deg) << "</td>";
    for (const auto& m : r.models)
      h << "<td>" << fmt(m.normalized[i].rms_log) << " (" << fmt(m.absolute[i].rms_log) << ")</td>";
    h << "</tr>\n";
  }
  if (!r.fits.empty()) {
    h << "</table>\n<h2>Fit: at most four parameters per model, same objective</h2>\n"
         "<p>Objective: RMS of ln(model / measured), absolute, of the inner model; then the fitted "
         "parameters at the run's quality (the models marked fitted above).</p>\n<table><tr>"
         "<th>model</th><th>parameter</th><th>start</th><th>box</th><th>fitted</th><th>sigma</th>"
         "<th>sigma over restarts</th></tr>\n";
    for (const auto& f : r.fits)
      for (const auto& p : f.parameters)
        h << "<tr><td>" << html_escape(f.model) << "</td><td>" << html_escape(p.parameter.name)
          << (p.parameter.unit.empty() ? "" : " (" + html_escape(p.parameter.unit) + ")")
          << "</td><td>" << fmt(p.parameter.start, 4) << "</td><td>[" << fmt(p.parameter.lo, 4)
          << ", " << fmt(p.parameter.hi, 4) << "]</td><td>" << fmt(p.value, 4)
          << (p.at_bound ? " (at bound)" : "") << "</td><td>"
          << (std::isfinite(p.sigma) ? fmt(p.sigma, 2) : std::string("&mdash;")) << "</td><td>"
          << (std::isfinite(p.sigma_restarts) ? fmt(p.sigma_restarts, 2) : std::string("&mdash;"))
          << "</td></tr>\n";
    h << "</table>\n<table><tr><th>model</th><th>search</th><th>inner RMS log, "
         "start</th><th>inner RMS log, fitted</th><th>evaluations</th><th>converged</th>"
         "<th>seconds</th></tr>\n";
    for (const auto& f : r.fits)
      h << "<tr><td>" << html_escape(f.model) << "</td><td>" << html_escape(f.method) << "</td><td>"
        << fmt(f.objective_start) << "</td><td>" << fmt(f.objective) << "</td><td>" << f.evaluations
        << "</td><td>" << (f.converged ? "yes" : "no") << "</td><td>" << fmt(f.seconds, 4)
        << "</td></tr>\n";
    h << "</table>\n<p>Inner models: ";
    for (const auto& f : r.fits)
      h << html_escape(f.model) << ": " << html_escape(f.inner_model) << ". ";
    h << "Uncertainty: " << html_escape(r.fits.front().uncertainty) << ".</p>\n<table>";
  }
  h << "</table>\n<h2>In-plane curves</h2>\n<p>beta / pi against the view zenith (positive on "
       "the mirror side), one panel per incidence and channel; error bars one standard "
       "error.</p>\n";
  for (const auto& [name, bytes] : images) {
    const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
    h << "<h3>" << html_escape(name) << "</h3>\n<img alt=\"" << html_escape(name)
      << "\" src=\"data:image/png;base64," << base64(std::span<const uint8_t>(p, bytes.size()))
      << "\">\n";
  }
  if (!r.renders.empty()) {
    h << "<h2>Renders of the sample (paper's Figs. 8-9)</h2>\n";
    // The flat patches with the fabric tables, then the fibers with the fiber tables.
    for (const char* kind : {"patch", "weave"}) {
      const bool weave = std::string(kind) == "weave";
      if (std::none_of(r.renders.begin(), r.renders.end(),
                       [&](const VerifyRender& v) { return v.kind == kind; }))
        continue;
      if (weave) h << "<h3>The fibers of the woven sample</h3>\n";
      h << "<p>" << html_escape(weave ? kVerifyWeaveRenderSetup : kVerifyRenderSetup)
        << "</p>\n<table><tr><th>render</th><th>what</th><th>"
        << (weave ? "mean" : "patch radiance") << " (linear sRGB)</th></tr>\n";
      for (const auto& v : r.renders) {
        if (v.kind != kind) continue;
        const Rgb c = weave ? v.mean : v.patch_radiance;
        h << "<tr><td><a href=\"" << html_escape(v.stem) << ".exr\"><img src=\""
          << html_escape(v.stem) << ".png\" alt=\"" << html_escape(v.stem)
          << "\" style=\"width:" << (weave ? 320 : 160) << "px\"></a></td><td>"
          << html_escape(v.caption) << "<br>" << html_escape(v.stem)
          << ".png (.exr: linear)</td><td>" << fmt(c.r) << ", " << fmt(c.g) << ", " << fmt(c.b)
          << "</td></tr>\n";
      }
      h << "</table>\n";
    }
  }
  h << "<h2>Colour (paper's Table 1): CIE 1931, D65</h2>\n<table><tr><th>what</th><th>linear "
       "sRGB</th><th>H</th><th>S</th><th>V</th><th></th><th>note</th></tr>\n";
  for (const auto& c : r.colours) {
    h << "<tr><td>" << html_escape(c.name) << "</td><td>";
    if (std::isfinite(c.linear_srgb.r))
      h << fmt(c.linear_srgb.r) << ", " << fmt(c.linear_srgb.g) << ", " << fmt(c.linear_srgb.b);
    else
      h << "&mdash;";
    // A swatch: HSV to display RGB.
    const double hh = c.hsv.h * 6, cc = c.hsv.v * c.hsv.s;
    const double x = cc * (1 - std::abs(std::fmod(hh, 2.0) - 1)), mm = c.hsv.v - cc;
    double rr = 0, gg = 0, bb = 0;
    const int sector = static_cast<int>(hh) % 6;
    if (sector == 0)
      rr = cc, gg = x;
    else if (sector == 1)
      rr = x, gg = cc;
    else if (sector == 2)
      gg = cc, bb = x;
    else if (sector == 3)
      gg = x, bb = cc;
    else if (sector == 4)
      rr = x, bb = cc;
    else
      rr = cc, bb = x;
    auto byte = [&](double v) {
      return std::clamp(static_cast<int>(std::lround(255 * linear_to_srgb_gamma(v + mm))), 0, 255);
    };
    char swatch[96];
    std::snprintf(swatch, sizeof swatch, "background:rgb(%d,%d,%d);width:3em", byte(rr), byte(gg),
                  byte(bb));
    h << "</td><td>" << fmt(c.hsv.h) << "</td><td>" << fmt(c.hsv.s) << "</td><td>" << fmt(c.hsv.v)
      << "</td><td style=\"" << swatch << "\"></td><td>" << html_escape(c.note) << "</td></tr>\n";
  }
  h << "</table>\n<p>Classic diffuse colour (linear sRGB): " << fmt(r.classic_reflectance.r) << ", "
    << fmt(r.classic_reflectance.g) << ", " << fmt(r.classic_reflectance.b) << " ("
    << r.classic_clip.components << " components clipped to [0, 1]); from "
    << html_escape(r.classic_source) << ".</p>\n";
  const VerifySettings& s = r.settings;
  h << "<h2>Settings, seed and timings</h2>\n<table>"
    << "<tr><td>quality</td><td>" << quality_name(s.quality) << "</td></tr>"
    << "<tr><td>table resolution R</td><td>" << s.resolution << "</td></tr>"
    << "<tr><td>fiber photons per band</td><td>" << s.fiber_photons_per_band << "</td></tr>"
    << "<tr><td>ray-trace particles per incident bin (all batches)</td><td>" << s.particles_per_bin
    << "</td></tr><tr><td>batches</td><td>" << s.batches
    << "</td></tr><tr><td>summation samples per cell pair</td><td>" << s.summation_samples
    << "</td></tr><tr><td>planes of incidence averaged</td><td>" << s.azimuths
    << "</td></tr><tr><td>seed</td><td>" << s.seed << "</td></tr><tr><td>threads</td><td>"
    << s.threads << "</td></tr><tr><td>ray-trace relative noise</td><td>"
    << fmt(r.raytrace_relative_noise) << "</td></tr>\n";
  for (const auto& [k, v] : r.seconds)
    h << "<tr><td>" << html_escape(k) << " (s)</td><td>" << fmt(v, 4) << "</td></tr>";
  h << "</table>\n</body></html>\n";
  return h.str();
}

void check_verify_output(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target = fs::absolute(dir);
  const fs::path parent = target.parent_path();
  if (!fs::is_directory(parent, ec))
    throw Error(dir.string(), "-o", "the output's parent directory does not exist");
  if (fs::exists(target, ec)) {
    if (!fs::is_directory(target, ec))
      throw Error(dir.string(), "-o", "exists and is not a directory");
    if (!fs::is_empty(target, ec)) {
      std::ifstream m(target / "metrics.json");
      nlohmann::json j = nlohmann::json::parse(m, nullptr, false);
      if (j.is_discarded() || !j.is_object() || j.value("report", "") != "weft verify")
        throw Error(dir.string(), "-o",
                    "exists and holds something other than an earlier weft verify report; "
                    "refusing to replace it");
    }
  }
}

void write_verify_report(const std::filesystem::path& dir, const VerifyReport& report,
                         const std::function<void(const std::filesystem::path&)>& draw) {
  namespace fs = std::filesystem;
  check_verify_output(dir);
  std::error_code ec;
  const fs::path target = fs::absolute(dir);
  // A staging folder named as atomic_file.h names temporaries, so that one a killed run left is
  // removed by the next; the earlier report moved aside is never removed that way.
  const fs::path staging = temporary_sibling(target);
  const fs::path old = fs::path(staging.string() + "-old");
  try {
    if (!fs::create_directory(staging, ec) || ec)
      throw Error(dir.string(), "-o", "cannot create a staging folder beside it");
    // The renders first, so that metrics.json and index.html describe them and their time.
    VerifyReport r = report;
    const auto t0 = std::chrono::steady_clock::now();
    r.renders = render_verify_samples(staging, r);
    for (const auto& v : r.renders) {
      write_exr(staging / (v.stem + ".exr"), v.image);
      write_png_preview(staging / (v.stem + ".png"), v.image, kVerifyRenderExposure);
    }
    r.seconds["renders"] = seconds_since(t0);
    write_text_atomically(staging / "inplane.csv", verify_inplane_csv(r));
    write_text_atomically(staging / "metrics.json", verify_metrics_json(r));
    draw(staging);
    std::vector<std::pair<std::string, std::string>> images;
    std::vector<fs::path> pngs;
    // The plots are embedded; the renders are linked (relative paths) beside their EXR.
    for (const auto& e : fs::directory_iterator(staging))
      if (e.path().extension() == ".png" && e.path().filename().string().rfind("render-", 0) != 0)
        pngs.push_back(e.path());
    std::sort(pngs.begin(), pngs.end());
    for (const auto& p : pngs) {
      std::ifstream f(p, std::ios::binary);
      std::ostringstream b;
      b << f.rdbuf();
      images.emplace_back(p.filename().string(), b.str());
    }
    write_text_atomically(staging / "index.html", verify_index_html(r, images));
    // The earlier report (if any) is moved aside, the new one moved in, the old one removed.
    if (fs::exists(target, ec)) {
      fs::rename(target, old, ec);
      if (ec) throw Error(dir.string(), "-o", "cannot move the earlier report aside");
    }
    fs::rename(staging, target, ec);
    if (ec) throw Error(dir.string(), "-o", "cannot move the finished report into place");
  } catch (...) {
    fs::remove_all(staging, ec);
    if (fs::exists(old, ec) && !fs::exists(target, ec)) fs::rename(old, target, ec);
    throw;
  }
  fs::remove_all(old, ec);
}

}  // namespace weft
