// weft verify's lines for a terminal: the estimate before the work and the summary after it.
#include "weft/verify/summary_text.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "weft/core/run_limits.h"
#include "weft/verify/models.h"
#include "weft/verify/report.h"

namespace weft {
namespace {

// printf into 'out'.
__attribute__((format(printf, 2, 3))) void append(std::string& out, const char* format, ...) {
  char b[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(b, sizeof b, format, args);
  va_end(args);
  out += b;
}

// "0.308 +- 0.005 [0.29..0.35]": a figure, its seed standard error, its range over the fits.
std::string figure_text(const FigureSamples& f) {
  std::string t;
  append(t, "%.3f +- %.3f", f.value(), f.seed_se());
  if (f.mean.size() > 1) append(t, " [%.2f..%.2f]", f.fit_min(), f.fit_max());
  return t;
}

// The verdict, then the headline figures of each model with their uncertainty.
void verdict_text(std::string& out, const VerifyReport& report) {
  const std::vector<Verdict> verdicts = verify_verdicts(report);
  const VerifyVerdictContext context = verify_verdict_context(report);
  out += "  verdict:\n";
  if (context.no_model_describes)
    append(out,
           "   no model here describes this sample (every model's shape RMS log is above %.3g): "
           "none is named closer\n",
           kNoModelShapeRmsLog);
  out += "   the measurement's own spread between its fits:";
  for (int f = 0; f < 3; ++f) {
    if (std::isfinite(context.measured_spread[f]))
      append(out, " %s %.3f", kFigureKeys[f], context.measured_spread[f]);
    else
      append(out, " %s unknown (one fit; %.3f required)", kFigureKeys[f], kMinBundledFitSpread[f]);
  }
  out += "\n";
  for (int f = 0; f < 3; ++f) {
    const std::string note =
        f == kAbsoluteFigure ? not_comparable_note(report.measured.colour_space) : "";
    append(out, "   %s%s\n", figure_label(static_cast<FigureKind>(f)).c_str(),
           note.empty() ? "" : (" -- " + note).c_str());
    for (const Verdict& v : verdicts)
      if (v.figure == kFigureKeys[f]) append(out, "    - %s\n", v.text.c_str());
  }
  append(
      out, "  %-36s %-28s %-28s %-28s %s\n", "RMS log (+- seed SE [over fits])", "shape",
      "paper's one-point",
      absolute_comparable(report.measured.colour_space) ? "absolute" : "absolute (not comparable)",
      "floored");
  for (const auto& m : report.models)
    if (!m.figures.fits.empty())
      append(out, "  %-36s %-28s %-28s %-28s %zu\n", m.label.c_str(),
             figure_text(m.figures.figure[kShapeFigure]).c_str(),
             figure_text(m.figures.figure[kPaperFigure]).c_str(),
             figure_text(m.figures.figure[kAbsoluteFigure]).c_str(), m.figures.log_floored_points);
}

// Each fit: its objective, evaluations and parameters with their spread over the seeds' fits.
void fits_text(std::string& out, const VerifyReport& report) {
  for (const auto& f : report.fits) {
    append(out, "  fit %s: inner rms_log %.3f -> %.3f, %d evaluations, %.1f s", f.model.c_str(),
           f.objective_start, f.objective, f.evaluations, f.seconds);
    if (f.seed_fits.size() > 1)
      append(out, ", kept seed %llu of %zu fits",
             static_cast<unsigned long long>(f.seed_fits.front().seed), f.seed_fits.size());
    out += ":";
    for (const auto& fp : f.parameters) {
      append(out, " %s %.4g +- %.2g%s", fp.parameter.name.c_str(), fp.value, fp.sigma,
             fp.at_bound ? " (at bound)" : "");
      // The spread over the seeds' fits: what the measurement leaves undetermined shows here.
      if (std::isfinite(fp.sigma_seeds))
        append(out, " [fits %.4g..%.4g]", fp.seeds_lo, fp.seeds_hi);
    }
    out += "\n";
  }
}

}  // namespace

std::string verify_estimate_text(const VerifyPlan& p) {
  const VerifyRequest& r = p.request;
  const VerifyEstimate e = estimate_verify(p);
  std::string out;
  append(out,
         "weft verify: quality %s%s, %.3g M photons and %.3g M particles: about %s on %u cores "
         "(%s of CPU; at least %s)",
         r.quality.c_str(), r.fit ? " with --fit" : "", e.photons * 1e-6, e.particles * 1e-6,
         format_seconds(e.typical / e.cores).c_str(), e.cores, format_seconds(e.typical).c_str(),
         format_seconds(e.least / e.cores).c_str());
  // The sample's size drives its scene's memory and every ray's time: a large draft's own cost.
  if (e.scene_bytes > 0)
    append(out, "; a sample of %.3g M fiber segments, its scene about %s", e.fiber_segments * 1e-6,
           format_bytes(e.scene_bytes).c_str());
  out += "\n";
  return out;
}

std::string verify_summary_text(const VerifyPlan& p, const VerifyReport& report, double seconds) {
  std::string out;
  append(out, "%s: %zu incidences, quality %s, %.1f s\n", p.request.output.c_str(),
         p.measured.curves.size(), p.request.quality.c_str(), seconds);
  verdict_text(out, report);
  append(out, "  %-36s %10s %10s %10s %10s\n", "RMS vs measured", "log norm", "rel norm", "log abs",
         "rel abs");
  for (const VerifyModelNames& names : kVerifyModels) {
    const std::string key = names.key;
    const auto m = std::find_if(report.models.begin(), report.models.end(),
                                [&](const ModelCurves& c) { return c.key == key; });
    if (m != report.models.end())
      append(out, "  %-36s %10.3f %10.3f %10.3f %10.3f\n", m->label.c_str(),
             m->normalized_overall.rms_log, m->normalized_overall.rms_rel,
             m->absolute_overall.rms_log, m->absolute_overall.rms_rel);
  }
  fits_text(out, report);
  return out;
}

}  // namespace weft
