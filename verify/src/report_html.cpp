// index.html of the report: an offline page, the plots embedded, the renders linked.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common.h"
#include "weft/core/hash.h"
#include "weft/verify/report.h"

namespace weft {
namespace {

// The page's head and what was compared.
void html_head(std::ostringstream& h, const VerifyReport& r) {
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>weft verify</title>\n"
       "<style>body{font-family:sans-serif;max-width:1400px;margin:auto}table{border-collapse:"
       "collapse}td,th{border:1px solid #aaa;padding:3px 8px;text-align:right}"
       "td:first-child,th:first-child{text-align:left}img{max-width:100%}</style></head><body>\n";
  h << "<h1>weft verify: computed fabric vs measurement vs classic model</h1>\n";
  h << "<p>Measurement: " << html_escape(r.measured.file)
    << "<br>Fiber: " << html_escape(r.fiber_name) << "<br>Sample: " << html_escape(r.sample_name)
    << "</p>\n";
}

// The metrics of every model, overall and per incidence (the table is left open).
void html_metrics(std::ostringstream& h, const VerifyReport& r) {
  h << "<h2>All metrics (over every view, incidence and channel)</h2>\n<table><tr><th>model</th>"
       "<th>RMS log ratio, normalized</th><th>RMS relative, normalized</th><th>RMS log ratio, "
       "absolute"
    << (absolute_judged(r) ? "" : " (not comparable)") << "</th><th>RMS relative, absolute"
    << (absolute_judged(r) ? "" : " (not comparable)")
    << "</th><th>normalization factor (R, G, B)</th>"
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
}

// The fits: parameters, searches and inner models (the table is left open).
void html_fits(std::ostringstream& h, const VerifyReport& r) {
  if (!r.fits.empty()) {
    h << "</table>\n<h2>Fit: at most four parameters per model, same objective</h2>\n"
         "<p>Objective: RMS of ln(model / measured), absolute, of the inner model; then the fitted "
         "parameters at the run's quality (the models marked fitted above).</p>\n<table><tr>"
         "<th>model</th><th>parameter</th><th>start</th><th>box</th><th>fitted</th><th>sigma</th>"
         "<th>sigma over restarts</th><th>over the seeds' fits: range (sd)</th></tr>\n";
    for (const auto& f : r.fits)
      for (const auto& p : f.parameters)
        h << "<tr><td>" << html_escape(f.model) << "</td><td>" << html_escape(p.parameter.name)
          << (p.parameter.unit.empty() ? "" : " (" + html_escape(p.parameter.unit) + ")")
          << "</td><td>" << fmt(p.parameter.start, 4) << "</td><td>[" << fmt(p.parameter.lo, 4)
          << ", " << fmt(p.parameter.hi, 4) << "]</td><td>" << fmt(p.value, 4)
          << (p.at_bound ? " (at bound)" : "") << "</td><td>"
          << (std::isfinite(p.sigma) ? fmt(p.sigma, 2) : std::string("&mdash;")) << "</td><td>"
          << (std::isfinite(p.sigma_restarts) ? fmt(p.sigma_restarts, 2) : std::string("&mdash;"))
          << "</td><td>"
          << (std::isfinite(p.sigma_seeds) ? fmt(p.seeds_lo, 3) + " &ndash; " + fmt(p.seeds_hi, 3) +
                                                 " (" + fmt(p.sigma_seeds, 2) + ")"
                                           : std::string("&mdash;"))
          << "</td></tr>\n";
    h << "</table>\n<table><tr><th>model</th><th>search</th><th>inner RMS log, "
         "start</th><th>inner RMS log, fitted</th><th>the same, mean over the seeds</th>"
         "<th>seeds</th><th>evaluations</th><th>converged</th><th>seconds</th></tr>\n";
    for (const auto& f : r.fits)
      h << "<tr><td>" << html_escape(f.model) << "</td><td>" << html_escape(f.method) << "</td><td>"
        << fmt(f.objective_start) << "</td><td>" << fmt(f.objective) << "</td><td>"
        << (f.seed_fits.empty() ? std::string("&mdash;")
                                : fmt(f.seed_fits.front().objective_over_seeds))
        << "</td><td>" << f.seed_fits.size() << "</td><td>" << f.evaluations << "</td><td>"
        << (f.converged ? "yes" : "no") << "</td><td>" << fmt(f.seconds, 4) << "</td></tr>\n";
    h << "</table>\n<p>Inner models: ";
    for (const auto& f : r.fits)
      h << html_escape(f.model) << ": " << html_escape(f.inner_model) << ". ";
    h << "Uncertainty: " << html_escape(r.fits.front().uncertainty) << ".</p>\n<table>";
  }
}

// The plots of the in-plane curves, embedded: one figure per incidence, in a grid of figures
// wide enough to read, each linked to its file at full size.
void html_curves(std::ostringstream& h,
                 const std::vector<std::pair<std::string, std::string>>& images) {
  h << "</table>\n<h2>In-plane curves</h2>\n<p>beta / pi against the view zenith (positive on "
       "the mirror side), one figure per incidence: a panel per channel, the paper's "
       "normalization above (each model's factors in the legend), absolute below on a log axis "
       "(values &le; 0 or not finite cannot be drawn there: each panel's title counts them); "
       "the dashed line is the mirror direction; error bars one standard error. Click a figure "
       "for its full size.</p>\n<div style=\"display:grid;grid-template-columns:repeat(auto-fill,"
       "minmax(680px,1fr));gap:8px\">\n";
  for (const auto& [name, bytes] : images) {
    const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
    h << "<a href=\"" << html_escape(name) << "\"><img alt=\"" << html_escape(name)
      << "\" src=\"data:image/png;base64," << base64(std::span<const uint8_t>(p, bytes.size()))
      << "\"></a>\n";
  }
  h << "</div>\n";
}

// The renders of the sample, linked beside their EXR.
void html_renders(std::ostringstream& h, const VerifyReport& r) {
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
  if (!r.previews.empty()) {
    h << "<h2>The fabric tables in 3-D</h2>\n<p>Each model's fabric table as weft view shows it: "
         "the glTF material fitted to it on a cushion and a draped cloth, beside its in-plane "
         "curves at an incidence chosen on the page (offline pages beside this one).</p>\n<ul>\n";
    for (const auto& p : r.previews)
      h << "<li><a href=\"" << html_escape(p.file) << "\">" << html_escape(p.file)
        << "</a>: " << html_escape(p.label) << "</li>\n";
    h << "</ul>\n";
  } else if (!r.previews_skipped.empty()) {
    h << "<p>No 3-D previews of the fabric tables: " << html_escape(r.previews_skipped) << "</p>\n";
  }
}

// A colour swatch's style: the HSV colour as display RGB.
std::string swatch_style(const Hsv& hsv) {
  const double hh = hsv.h * 6, cc = hsv.v * hsv.s;
  const double x = cc * (1 - std::abs(std::fmod(hh, 2.0) - 1)), mm = hsv.v - cc;
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
  return swatch;
}

// The colour table (paper's Table 1) and the classic diffuse colour.
void html_colours(std::ostringstream& h, const VerifyReport& r) {
  h << "<h2>Colour (paper's Table 1): CIE 1931, D65</h2>\n<table><tr><th>what</th><th>RGB</th>"
       "<th>RGB space</th><th>H</th><th>S</th><th>V</th><th></th><th>note</th></tr>\n";
  for (const auto& c : r.colours) {
    h << "<tr><td>" << html_escape(c.name) << "</td><td>";
    if (std::isfinite(c.rgb.r))
      h << fmt(c.rgb.r) << ", " << fmt(c.rgb.g) << ", " << fmt(c.rgb.b);
    else
      h << "&mdash;";
    h << "</td><td>" << html_escape(c.colour_space) << (c.comparable ? "" : " (not comparable)")
      << "</td><td>" << fmt(c.hsv.h) << "</td><td>" << fmt(c.hsv.s) << "</td><td>" << fmt(c.hsv.v)
      << "</td><td style=\"" << swatch_style(c.hsv) << "\"></td><td>" << html_escape(c.note)
      << "</td></tr>\n";
  }
  h << "</table>\n<p>Classic diffuse colour (linear sRGB): " << fmt(r.classic_reflectance.r) << ", "
    << fmt(r.classic_reflectance.g) << ", " << fmt(r.classic_reflectance.b) << " ("
    << r.classic_clip.components
    << " components clipped to [0, 1]: a fitted reflectance's physical bound); from "
    << html_escape(r.classic_source)
    << ".</p>\n<p>Computed fabric table in linear sRGB: " << r.fabric_table_gamut_clipped
    << " components clipped; " << r.fabric_table_out_of_gamut.components
    << " lie outside the sRGB gamut (below 0, largest magnitude "
    << fmt(r.fabric_table_out_of_gamut.largest)
    << ") and are kept as they are; the log figures floor them.</p>\n";
}

// The settings, seed and timings.
void html_settings(std::ostringstream& h, const VerifyReport& r) {
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
  h << "</table>\n";
}

}  // namespace

std::string verify_index_html(const VerifyReport& r,
                              const std::vector<std::pair<std::string, std::string>>& images) {
  std::ostringstream h;
  html_head(h, r);
  html_verdict(h, r);
  html_metrics(h, r);
  html_fits(h, r);
  html_curves(h, images);
  html_renders(h, r);
  html_colours(h, r);
  html_settings(h, r);
  h << "</body></html>\n";
  return h.str();
}

}  // namespace weft
