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

namespace {
// The three figures of 'model' against 'ref', in kFigureKeys order.
std::array<double, 3> three_figures(const InplaneCurves& model, const InplaneCurves& ref,
                                    const MeasuredInplane& geometry, NormalIndex normal) {
  return {shape_figure(model, ref, geometry).rms_log, paper_figure(model, ref, normal),
          absolute_figure(model, ref)};
}

}  // namespace

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
  const LogFloored floored_mean = floor_for_log(mean);
  out.log_floored_points = floored_mean.floored;
  std::vector<InplaneCurves> floored_batches;
  for (const auto& b : batches) floored_batches.push_back(floor_for_log(b).curves);
  for (const MeasuredFit& fit : measured_fits(measured)) {
    const InplaneCurves ref = floor_for_log(fit.beta).curves;
    out.fits.push_back(fit.name);
    if (out.fits.size() == 1) out.shape = shape_figure(floored_mean.curves, ref, measured);
    const auto f = three_figures(floored_mean.curves, ref, measured, normal);
    for (int k = 0; k < 3; ++k) {
      out.figure[k].mean.push_back(f[k]);
      if (!batches.empty()) out.figure[k].batch.emplace_back();
    }
    for (const auto& b : floored_batches) {
      const auto fb = three_figures(b, ref, measured, normal);
      for (int k = 0; k < 3; ++k) out.figure[k].batch.back().push_back(fb[k]);
    }
  }
  return out;
}

std::array<double, 3> measured_fit_spread(const MeasuredInplane& measured, NormalIndex normal) {
  std::array<double, 3> spread{kNaN, kNaN, kNaN};
  std::vector<InplaneCurves> fits;
  for (const MeasuredFit& fit : measured_fits(measured))
    fits.push_back(floor_for_log(fit.beta).curves);
  for (size_t a = 0; a < fits.size(); ++a)
    for (size_t b = a + 1; b < fits.size(); ++b) {
      const auto f = three_figures(fits[a], fits[b], measured, normal);
      // A figure not defined between two fits leaves the spread undefined.
      const bool first = a == 0 && b == 1;
      for (int k = 0; k < 3; ++k)
        spread[k] = first || std::isnan(f[k]) || std::isnan(spread[k]) ? (first ? f[k] : kNaN)
                                                                       : std::max(spread[k], f[k]);
    }
  return spread;
}

std::optional<NormalIndex> normal_index(const MeasuredInplane& measured) {
  for (size_t i = 0; i < measured.curves.size(); ++i)
    for (size_t v = 0; v < measured.curves[i].view_deg.size(); ++v)
      if (measured.curves[i].theta_i_deg == 0 && measured.curves[i].view_deg[v] == 0)
        return NormalIndex{i, v};
  return std::nullopt;
}

LogFloored floor_for_log(const InplaneCurves& curves) {
  LogFloored out{curves, 0};
  std::array<double, 3> channel_max{};
  for (const auto& curve : curves)
    for (const Rgb& b : curve)
      for (int k = 0; k < 3; ++k) channel_max[k] = std::max(channel_max[k], b[k]);
  const double largest = *std::max_element(channel_max.begin(), channel_max.end());
  for (int k = 0; k < 3; ++k) {
    // A channel with no positive value (a colour far outside the gamut) takes the brightest
    // channel's maximum; curves with no light at all have no floor and stay excluded.
    const double top = channel_max[k] > 0 ? channel_max[k] : largest;
    if (!(top > 0)) continue;
    const double floor = kLogFloorFraction * top;
    for (auto& curve : out.curves)
      for (Rgb& b : curve)
        if (b[k] < floor) {
          b[k] = floor;
          ++out.floored;
        }
  }
  return out;
}

}  // namespace weft
