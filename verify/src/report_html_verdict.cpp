// The verdict that leads the report's page: in words, then the headline figures of every model
// with their uncertainty, each labelled for what it is.
#include <cmath>
#include <sstream>

#include "common.h"
#include "weft/verify/report.h"

namespace weft {
namespace {

// "0.31 +- 0.01 [0.29..0.35]": the figure, its seed standard error, its range over the fits.
std::string figure_cell(const FigureSamples& f) {
  std::string c = fmt(f.value()) + " &plusmn; " + fmt(f.seed_se(), 1);
  if (f.mean.size() > 1) c += " [" + fmt(f.fit_min()) + "&ndash;" + fmt(f.fit_max()) + "]";
  return c;
}

void figures_table(std::ostringstream& h, const VerifyReport& r) {
  h << "<table><tr><th>model</th><th>shape, RMS log (|view| &le; " << fmt(kShapeMaxViewDeg)
    << "&deg;)</th><th>shape beyond " << fmt(kShapeMaxViewDeg)
    << "&deg; (same gains)</th><th>shape gains (R, G, B)</th><th>paper's one-point "
       "normalization, RMS log</th><th>absolute, RMS log"
    << (absolute_judged(r) ? "" : " (not comparable)") << "</th><th>points floored</th></tr>\n";
  for (const auto& m : r.models) {
    if (m.figures.fits.empty()) continue;
    const ShapeFigure& s = m.figures.shape;
    h << "<tr><td>" << html_escape(m.label) << "</td><td>"
      << figure_cell(m.figures.figure[kShapeFigure]) << "</td><td>" << fmt(s.rms_log_grazing)
      << "</td><td>" << fmt(s.gain.r) << ", " << fmt(s.gain.g) << ", " << fmt(s.gain.b)
      << "</td><td>" << figure_cell(m.figures.figure[kPaperFigure]) << "</td><td>"
      << figure_cell(m.figures.figure[kAbsoluteFigure]) << "</td><td>"
      << m.figures.log_floored_points << "</td></tr>\n";
  }
  h << "</table>\n";
}

// The measurement's own spread per figure, or what stands in for it with one fit.
std::string spread_sentence(const VerifyVerdictContext& c) {
  std::string s;
  for (int f = 0; f < 3; ++f)
    s += (f ? "; " : "") + figure_name(static_cast<FigureKind>(f)) + " " +
         (std::isfinite(c.measured_spread[f])
              ? fmt(c.measured_spread[f], 2)
              : "unknown (one fit), at least " + fmt(kMinBundledFitSpread[f], 2) + " required");
  return s;
}

}  // namespace

void html_verdict(std::ostringstream& h, const VerifyReport& r) {
  const std::vector<Verdict> verdicts = verify_verdicts(r);
  const VerifyVerdictContext context = verify_verdict_context(r);
  h << "<h2>Verdict</h2>\n";
  if (context.no_model_describes)
    h << "<p><b>No model here describes this sample</b>: every model's shape figure is above "
      << fmt(kNoModelShapeRmsLog) << " RMS log, so no verdict names a closer model.</p>\n";
  for (int f = 0; f < 3; ++f) {
    const bool shown_apart = f == kAbsoluteFigure && !absolute_judged(r);
    h << "<p><b>" << html_escape(figure_label(static_cast<FigureKind>(f))) << "</b>"
      << (shown_apart ? " &mdash; <b>" + html_escape(not_comparable_note(r.measured.colour_space)) +
                            "</b> (shown for what it is)"
                      : "")
      << "</p>\n<ul>";
    for (const Verdict& v : verdicts)
      if (v.figure == kFigureKeys[f]) h << "<li>" << html_escape(v.text) << "</li>";
    h << "</ul>\n";
  }
  std::string fits;
  if (!r.models.empty())
    for (const auto& name : r.models.front().figures.fits)
      fits += (fits.empty() ? "" : ", ") + name;
  h << "<p>Figures against the measurement's reference fit, &plusmn; the seed's standard error "
       "(the spread of the ray trace's "
    << r.settings.batches
    << " independent batches over the square root of their number); in brackets the figure "
       "against each fit of the measurement ("
    << html_escape(fits)
    << "): how far the figure moves with the reference. The measurement's own spread, the "
       "largest figure between two of its fits: "
    << html_escape(spread_sentence(context))
    << ". A verdict is resolved when the difference has one sign against every fit and for "
       "every batch, and exceeds both "
    << fmt(kVerdictSeedErrors)
    << " seed standard errors and the measurement's own spread; otherwise it is a tie. Log "
       "figures floor each channel at "
    << fmt(kLogFloorFraction)
    << " of its own maximum (linear sRGB is kept unclamped); the "
       "points floored are in the last column.</p>\n";
  figures_table(h, r);
}

}  // namespace weft
