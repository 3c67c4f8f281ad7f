#include "weft/verify/figures.h"

#include <algorithm>
#include <cmath>

#include "weft/verify/metrics.h"

namespace weft {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool usable(double model, double measured) {
  return model > 0 && measured > 0;
}

double rms(double sum2, size_t n) {
  return n ? std::sqrt(sum2 / static_cast<double>(n)) : kNaN;
}

// The model scaled per channel by 'factor' (the paper's normalization).
InplaneCurves scaled(const InplaneCurves& model, const Rgb& factor) {
  InplaneCurves out = model;
  for (auto& curve : out)
    for (auto& b : curve) b = b * factor;
  return out;
}

}  // namespace

ShapeFigure shape_figure(const InplaneCurves& model, const InplaneCurves& measured,
                         const MeasuredInplane& geometry) {
  ShapeFigure s;
  const auto inside = [&](size_t i, size_t v) {
    return std::abs(geometry.curves[i].view_deg[v]) <= kShapeMaxViewDeg;
  };
  // The gains: the mean log ratio per channel over the points inside.
  std::array<double, 3> sum_log{};
  std::array<size_t, 3> n{};
  for (size_t i = 0; i < geometry.curves.size(); ++i)
    for (size_t v = 0; v < geometry.curves[i].view_deg.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        if (!usable(model[i][v][k], measured[i][v][k])) {
          ++s.excluded;
          continue;
        }
        if (!inside(i, v)) continue;
        sum_log[k] += std::log(measured[i][v][k] / model[i][v][k]);
        ++n[k];
      }
  for (int k = 0; k < 3; ++k)
    s.gain[k] = n[k] ? std::exp(sum_log[k] / static_cast<double>(n[k])) : kNaN;
  // The residuals after the gains.
  std::array<double, 3> sum2_channel{};
  double sum2_grazing = 0;
  for (size_t i = 0; i < geometry.curves.size(); ++i) {
    double sum2 = 0;
    size_t points = 0;
    for (size_t v = 0; v < geometry.curves[i].view_deg.size(); ++v)
      for (int k = 0; k < 3; ++k) {
        if (!usable(model[i][v][k], measured[i][v][k]) || n[k] == 0) continue;
        const double r = std::log(s.gain[k] * model[i][v][k] / measured[i][v][k]);
        if (!inside(i, v)) {
          sum2_grazing += r * r;
          ++s.grazing_points;
          continue;
        }
        sum2 += r * r;
        sum2_channel[k] += r * r;
        ++points;
      }
    s.rms_log_incidence.push_back(rms(sum2, points));
  }
  double sum2_all = 0;
  for (int k = 0; k < 3; ++k) {
    s.rms_log_channel[k] = rms(sum2_channel[k], n[k]);
    sum2_all += sum2_channel[k];
    s.points += n[k];
  }
  s.rms_log = rms(sum2_all, s.points);
  s.rms_log_grazing = rms(sum2_grazing, s.grazing_points);
  return s;
}

double absolute_figure(const InplaneCurves& model, const InplaneCurves& measured) {
  MetricsAccumulator a;
  for (size_t i = 0; i < model.size(); ++i)
    for (size_t v = 0; v < model[i].size(); ++v)
      for (int k = 0; k < 3; ++k) a.add(model[i][v][k], measured[i][v][k]);
  return a.result().rms_log;
}

double paper_figure(const InplaneCurves& model, const InplaneCurves& measured, NormalIndex normal) {
  const Rgb m0 = model[normal.incidence][normal.view];
  const Rgb r0 = measured[normal.incidence][normal.view];
  Rgb factor;
  for (int k = 0; k < 3; ++k) {
    if (!(m0[k] > 0)) return kNaN;
    factor[k] = r0[k] / m0[k];
  }
  return absolute_figure(scaled(model, factor), measured);
}

double sample_sd(const std::vector<double>& values) {
  const size_t n = values.size();
  if (n < 2) return 0;
  double mean = 0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(n);
  double sum2 = 0;
  for (double v : values) sum2 += (v - mean) * (v - mean);
  return std::sqrt(sum2 / static_cast<double>(n - 1));
}

double FigureSamples::seed_sd() const {
  return batch.empty() ? 0.0 : sample_sd(batch.at(0));
}

double FigureSamples::seed_se() const {
  return batch.empty() ? 0.0 : seed_sd() / std::sqrt(static_cast<double>(batch.at(0).size()));
}

double FigureSamples::fit_min() const {
  return *std::min_element(mean.begin(), mean.end());
}
double FigureSamples::fit_max() const {
  return *std::max_element(mean.begin(), mean.end());
}

ModelFigures model_figures(const InplaneCurves& mean, const std::vector<InplaneCurves>& batches,
                           const MeasuredInplane& measured, NormalIndex normal) {
  ModelFigures out;
  const auto figures = [&](const InplaneCurves& model, const InplaneCurves& ref) {
    return std::array<double, 3>{shape_figure(model, ref, measured).rms_log,
                                 paper_figure(model, ref, normal), absolute_figure(model, ref)};
  };
  for (const MeasuredFit& fit : measured_fits(measured)) {
    out.fits.push_back(fit.name);
    if (out.fits.size() == 1) out.shape = shape_figure(mean, fit.beta, measured);
    const auto f = figures(mean, fit.beta);
    for (int k = 0; k < 3; ++k) {
      out.figure[k].mean.push_back(f[k]);
      if (!batches.empty()) out.figure[k].batch.emplace_back();
    }
    for (const auto& b : batches) {
      const auto fb = figures(b, fit.beta);
      for (int k = 0; k < 3; ++k) out.figure[k].batch.back().push_back(fb[k]);
    }
  }
  return out;
}

}  // namespace weft
