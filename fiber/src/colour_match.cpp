#include "weft/fiber/colour_match.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "weft/core/error.h"
#include "weft/core/optimize.h"
#include "weft/fiber/dye.h"
#include "weft/fiber/thread_colour.h"

namespace weft {

namespace {

// Kubelka-Munk's reflectance of an opaque layer of K/S = x, in the form that keeps its digits
// for large x: 1 + x - sqrt(x^2 + 2x) = 1 / (1 + x + sqrt(x^2 + 2x)).
double kubelka_munk(double x) {
  return 1.0 / (1.0 + x + std::sqrt(x * x + 2 * x));
}

// One band's model R = amplitude * KM(rate * mu).
struct BandModel {
  double amplitude = 0, rate = 0;
  double at(double mu) const { return amplitude * kubelka_munk(rate * mu); }
};

// The model through (mu1, r1) and (mu2, r2), mu1 < mu2: KM(q mu1) / KM(q mu2) = r1 / r2 solved for
// q by bisection in log q (the ratio rises from 1 at q = 0 to mu2 / mu1 as q grows). Readings
// that do not fall with mu (noise where the dyes hardly absorb) give a flat model at their mean.
BandModel fit_band(double mu1, double r1, double mu2, double r2) {
  if (!(r1 > 0 && r2 > 0) || r1 <= r2) return {0.5 * (r1 + r2), 0};
  const double want = std::log(r1 / r2);
  double lo = std::log(1e-9 / mu2), hi = std::log(1e9 / std::max(mu2, 1e-12));
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi), q = std::exp(mid);
    (std::log(kubelka_munk(q * mu1) / kubelka_munk(q * mu2)) < want ? lo : hi) = mid;
  }
  const double q = std::exp(0.5 * (lo + hi));
  return {r1 / kubelka_munk(q * mu1), q};
}

// The absorption per band of each reading's fibre.
using Absorptions = std::vector<Spectrum>;

// One band's reflectance as a function of its absorption through every reading: between two
// readings adjacent in mu the Kubelka-Munk model through both, beyond the ends the model
// through the two outermost, flat where the readings share one mu. Exact at every reading, so
// the steering sharpens as readings gather near the answer.
struct BandCurve {
  std::vector<double> mu;           // the readings' distinct absorptions, ascending
  std::vector<double> reflectance;  // at each (the mean where readings share one)
  std::vector<BandModel> pieces;    // pieces[i] between mu[i] and mu[i + 1]
  double at(double m) const {
    if (pieces.empty()) return reflectance.front();
    const size_t i = std::upper_bound(mu.begin() + 1, mu.end() - 1, m) - mu.begin() - 1;
    return pieces[i].at(m);
  }
};

std::vector<BandCurve> band_curves(const std::vector<ColourReading>& readings,
                                   const Absorptions& mu) {
  std::vector<BandCurve> curves(kNumBands);
  for (int b = 0; b < kNumBands; ++b) {
    std::vector<std::pair<double, double>> points;
    for (size_t k = 0; k < readings.size(); ++k)
      points.emplace_back(mu[k][b], readings[k].reflectance[b]);
    std::sort(points.begin(), points.end());
    BandCurve& c = curves[b];
    int shared = 0;
    for (const auto& [m, r] : points) {
      if (!c.mu.empty() && std::abs(m - c.mu.back()) <= 1e-9 * std::max(m, 1e-9)) {
        c.reflectance.back() = (c.reflectance.back() * (shared + 1) + r) / (shared + 2);
        ++shared;
        continue;
      }
      c.mu.push_back(m);
      c.reflectance.push_back(r);
      shared = 0;
    }
    for (size_t i = 0; i + 1 < c.mu.size(); ++i)
      c.pieces.push_back(fit_band(c.mu[i], c.reflectance[i], c.mu[i + 1], c.reflectance[i + 1]));
  }
  return curves;
}

// The scales' map from the unit cube, logarithmic from 1e-4 of the largest scale to it; the
// cube's floor is no dye at all. (It once was 1e-4 of the largest, 0.002 % owf: a dye the model
// left out was still read at that depth, and in a felt, where light walks long, 0.002 % of
// crystal violet and rhodamine B darkened a yellow by 5 L*.)
struct ScaleMap {
  std::vector<double> max_scale;
  static constexpr double kRange = 1e4;
  std::vector<double> scale(const std::vector<double>& u) const {
    std::vector<double> s(u.size());
    for (size_t d = 0; d < u.size(); ++d)
      s[d] = u[d] <= 0 ? 0.0 : max_scale[d] * std::pow(kRange, u[d] - 1);
    return s;
  }
  std::vector<double> unit(const std::vector<double>& s) const {
    std::vector<double> u(s.size());
    for (size_t d = 0; d < s.size(); ++d)
      u[d] = std::clamp(1 + std::log(std::max(s[d], 1e-300) / max_scale[d]) / std::log(kRange), 0.0,
                        1.0);
    return u;
  }
};

// The residuals of a reflectance against the target: its CIELAB difference, and for a spectrum
// target the band differences in percent too (a mixture should match the curve, not a metamer).
std::vector<double> target_residuals(const ColourTarget& t, const Spectrum& r) {
  const Lab lab = t.lab_of(r);
  std::vector<double> out{lab.l - t.lab.l, lab.a - t.lab.a, lab.b - t.lab.b};
  if (t.reflectance)
    for (int b = 0; b < kNumBands; ++b) out.push_back(100 * (r[b] - (*t.reflectance)[b]));
  return out;
}

// How far one step may move a scale from the best reading's (a factor either way).
constexpr double kTrustFactor = 8;
// A reading out of reach that brings the best's CIEDE2000 down by less than this share is idle;
// this many idle readings in a row end the match.
constexpr double kLeastGain = 0.05;
constexpr int kIdleReadings = 2;

struct ModelStep {
  std::vector<double> scale;
  double delta_e00 = 0;        // the model's own at its optimum
  bool at_trust_edge = false;  // the optimum lies on the trust region's edge inside the cube
};

// The scales at which the band models' colour is nearest the target, from the best reading's.
ModelStep model_step(const ColourMatch& m, const Spectrum& host_mu,
                     const std::vector<BandCurve>& models, const ScaleMap& map) {
  const auto reflectance = [&](const std::vector<double>& s) {
    Spectrum r{};
    for (int b = 0; b < kNumBands; ++b) {
      double mu = host_mu[b];
      for (size_t d = 0; d < s.size(); ++d) mu += s[d] * m.basis.absorption_per_um[d][b];
      r[b] = models[b].at(mu);
    }
    return r;
  };
  // A trust region: the model passes through every reading, so between them it interpolates and
  // beyond them it extrapolates; it is searched over the readings' span of each scale and a factor
  // kTrustFactor past it, and the next reading refits it further on. (Around the best reading
  // alone, a best reading of the undyed fibre held every step within a factor 8 of the smallest
  // scale, though the recipe's reading lay beyond the target.)
  const std::vector<double> u_best = map.unit(m.best_reading().scale);
  std::vector<double> lo(u_best), hi(u_best), v0(u_best.size());
  for (const ColourReading& r : m.readings) {
    const std::vector<double> u = map.unit(r.scale);
    for (size_t d = 0; d < u.size(); ++d)
      lo[d] = std::min(lo[d], u[d]), hi[d] = std::max(hi[d], u[d]);
  }
  // A dye added to the recipe (trichromatic_recipe) is at 0 in the first readings: until it has
  // been read above 0 it may go as deep as the recipe's deepest dye.
  const double deepest =
      *std::max_element(m.basis.initial_scale.begin(), m.basis.initial_scale.end());
  const std::vector<double> u_deepest =
      map.unit(std::vector<double>(u_best.size(), std::max(deepest, 1e-300)));
  const double reach = std::log(kTrustFactor) / std::log(ScaleMap::kRange);
  for (size_t d = 0; d < u_best.size(); ++d) {
    if (hi[d] <= 0) hi[d] = u_deepest[d];
    lo[d] = std::max(0.0, lo[d] - reach);
    hi[d] = std::min(1.0, hi[d] + reach);
    v0[d] = (u_best[d] - lo[d]) / (hi[d] - lo[d]);
  }
  const auto unit_of = [&](const std::vector<double>& v) {
    std::vector<double> u(v.size());
    for (size_t d = 0; d < v.size(); ++d) u[d] = lo[d] + v[d] * (hi[d] - lo[d]);
    return u;
  };
  const ResidualFunction residuals = [&](const std::vector<double>& v) {
    return target_residuals(m.target, reflectance(map.scale(unit_of(v))));
  };
  OptimizeOptions o;
  o.max_evaluations = 800;  // the model costs microseconds an evaluation
  o.tolerance = 1e-6;
  o.initial_step = 0.1;
  // Nelder-Mead: the model's colour is not smooth where a scale meets its bound.
  const OptimizeResult fit = nelder_mead(residuals, v0, o);
  ModelStep step;
  step.scale = map.scale(unit_of(fit.u));
  for (size_t d = 0; d < fit.u.size(); ++d)
    step.at_trust_edge |= (fit.u[d] < 1e-3 && lo[d] > 0) || (fit.u[d] > 1 - 1e-3 && hi[d] < 1);
  step.delta_e00 = delta_e00(m.target.lab, m.target.lab_of(reflectance(step.scale)));
  return step;
}

bool same_scales(const std::vector<double>& a, const std::vector<double>& b) {
  for (size_t d = 0; d < a.size(); ++d)
    if (std::abs(a[d] - b[d]) > 1e-3 * std::max(std::abs(a[d]), std::abs(b[d]))) return false;
  return true;
}

}  // namespace

void ColourMatchOptions::validate() const {
  if (!(tolerance_delta_e00 > 0 && tolerance_delta_e00 <= 50))
    throw Error("", "tolerance_delta_e00", "must be in (0, 50]");
  if (max_readings < 3 || max_readings > 64)
    throw Error("", "max_readings", "must be in [3, 64]: two readings set the model up");
}

DyeBasis dye_basis(const FiberSpec& spec) {
  DyeBasis basis;
  if (spec.dyes.empty()) {
    basis.recipe = false;
    const double chord_um = kPi * spec.fiber_radius_um / 2;  // Cauchy's mean chord
    for (int k = 0; k < 3; ++k) {
      Spectrum a = thread_colour_block(k);
      for (double& v : a) v *= std::log(2.0) / chord_um;
      basis.names.push_back(k == 0 ? "red-absorber" : k == 1 ? "green-absorber" : "blue-absorber");
      basis.absorption_per_um.push_back(a);
      basis.initial_scale.push_back(1);
      basis.max_scale.push_back(std::log(1 / kThreadMinReflectance) / std::log(2.0));
    }
    return basis;
  }
  for (const DyeComponent& c : spec.dyes) {
    DyeComponent unit = c;
    unit.concentration_owf_percent = 1;
    basis.names.push_back(c.dye);
    basis.absorption_per_um.push_back(
        dye_absorption_per_um(bundled_dye(c.dye, spec.name, "host.dyes").epsilon_per_M_per_cm,
                              dye_mol_per_L(unit, spec.density_g_cm3)));
    basis.initial_scale.push_back(c.concentration_owf_percent);
    basis.max_scale.push_back(kMaxDyeOwfPercent);
  }
  return basis;
}

FiberSpec trichromatic_recipe(const FiberSpec& spec) {
  if (spec.dyes.empty()) return spec;
  const std::string dye_class =
      bundled_dye(spec.dyes.front().dye, spec.name, "host.dyes").dye_class;
  bool has[3] = {false, false, false};
  for (const DyeComponent& c : spec.dyes) {
    const DyeSpectrum& d = bundled_dye(c.dye, spec.name, "host.dyes");
    if (d.dye_class.empty() || d.dye_class != dye_class) return spec;
    has[static_cast<int>(dye_hue(d))] = true;
  }
  constexpr double kHueMiddleNm[3] = {440, 520, 620};
  FiberSpec out = spec;
  for (int h = 0; h < 3; ++h) {
    if (has[h]) continue;
    std::string best;
    double best_distance = 0;
    for (const std::string& name : bundled_dye_names()) {
      const DyeSpectrum& d = bundled_dye(name, "", "dye");
      if (d.dye_class != dye_class || static_cast<int>(dye_hue(d)) != h) continue;
      const double distance = std::abs(dye_peak_nm(d) - kHueMiddleNm[h]);
      if (best.empty() || distance < best_distance) best = name, best_distance = distance;
    }
    if (!best.empty())
      out.dyes.push_back({.dye = best,
                          .concentration_owf_percent = 0,
                          .uptake_fraction = spec.dyes.front().uptake_fraction});
  }
  return out;
}

FiberSpec with_dye_scale(const FiberSpec& base, const DyeBasis& basis,
                         const std::vector<double>& scale) {
  FiberSpec s = base;
  if (basis.recipe) {
    for (size_t d = 0; d < s.dyes.size(); ++d) s.dyes[d].concentration_owf_percent = scale[d];
  } else {
    for (size_t d = 0; d < scale.size(); ++d)
      for (int b = 0; b < kNumBands; ++b)
        s.host_absorption_per_um[b] += scale[d] * basis.absorption_per_um[d][b];
  }
  s.name = base.name + " dyed";
  return s;
}

ColourMatch match_colour(const FiberSpec& base, const ColourTarget& target,
                         const ColourReadingFunction& read, const ColourMatchOptions& options) {
  options.validate();
  ColourMatch m;
  m.target = target;
  const FiberSpec recipe = options.complete_hues ? trichromatic_recipe(base) : base;
  m.basis = dye_basis(recipe);
  for (size_t d = base.dyes.size(); d < recipe.dyes.size(); ++d)
    m.added_dyes.push_back(recipe.dyes[d].dye);
  const size_t n = m.basis.names.size();
  const ScaleMap map{m.basis.max_scale};
  Absorptions mu;
  // Takes a reading at 'scale'; false when interrupted.
  const auto take = [&](const std::vector<double>& scale) {
    const std::clock_t cpu0 = std::clock();
    const FiberSpec spec = with_dye_scale(recipe, m.basis, scale);
    const std::optional<Spectrum> r = read(spec);
    if (!r) return false;
    ColourReading reading{scale, *r, target.lab_of(*r), 0,
                          static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC};
    reading.delta_e00 = delta_e00(target.lab, reading.lab);
    m.readings.push_back(reading);
    mu.push_back(host_total_absorption_per_um(spec));
    if (reading.delta_e00 < m.best_reading().delta_e00) m.best = m.readings.size() - 1;
    return true;
  };
  const Spectrum host_mu =
      host_total_absorption_per_um(with_dye_scale(recipe, m.basis, std::vector<double>(n, 0.0)));
  ModelStep last_step;
  int idle = 0;  // readings in a row that left the best where it was, while out of reach
  bool stalled = false, interrupted = !take(m.basis.initial_scale);
  // The undyed reading anchors the model; a recipe already on target needs none.
  if (!interrupted && m.best_reading().delta_e00 > options.tolerance_delta_e00)
    interrupted = !take(std::vector<double>(n, 0.0));
  while (!interrupted && !stalled && m.best_reading().delta_e00 > options.tolerance_delta_e00 &&
         static_cast<int>(m.readings.size()) < options.max_readings) {
    const ModelStep step = model_step(m, host_mu, band_curves(m.readings, mu), map);
    last_step = step;
    stalled = std::any_of(m.readings.begin(), m.readings.end(),
                          [&](const ColourReading& r) { return same_scales(r.scale, step.scale); });
    if (stalled) break;
    const double before = m.best_reading().delta_e00;
    interrupted = !take(step.scale);
    // Out of reach, the model keeps proposing colours about as far as the best reading's (its
    // optimum, away from the trust region's edge, is itself no closer than the tolerance): a
    // reading that gains under kLeastGain of the best's distance is idle, and two in a row end
    // the match, the best reading being then the nearest reachable colour.
    const bool model_out_of_reach =
        !step.at_trust_edge && step.delta_e00 > options.tolerance_delta_e00;
    idle =
        model_out_of_reach && m.best_reading().delta_e00 > (1 - kLeastGain) * before ? idle + 1 : 0;
    stalled = idle >= kIdleReadings;
  }
  m.cancelled = interrupted;
  if (m.readings.empty()) return m;
  m.reached = m.best_reading().delta_e00 <= options.tolerance_delta_e00;
  // Outside reach: even the model, free to move, stays away from the target.
  m.outside_reach = !m.reached && !m.cancelled && !last_step.at_trust_edge &&
                    last_step.delta_e00 > options.tolerance_delta_e00;
  m.spec = with_dye_scale(recipe, m.basis, m.best_reading().scale);
  return m;
}

nlohmann::json colour_match_summary(const ColourMatch& m) {
  const auto lab = [](const Lab& c) { return nlohmann::json::array({c.l, c.a, c.b}); };
  nlohmann::json j;
  j["target"] = {
      {"spec", m.target.spec},
      {"lab", lab(m.target.lab)},
      {"observer", m.target.observer == Observer::kCie1964TenDegree ? "CIE 1964 10 degrees"
                                                                    : "CIE 1931 2 degrees"}};
  std::string added;
  for (const std::string& d : m.added_dyes) added += (added.empty() ? "" : ", ") + d;
  j["basis"] = !m.basis.recipe ? "thread-colour absorbers"
               : added.empty() ? "the recipe's dyes (% owf)"
                               : "the recipe's dyes and " + added + " to make three hues (% owf)";
  j["added_dyes"] = m.added_dyes;
  j["reached"] = m.reached;
  j["outside_reach"] = m.outside_reach;
  j["cancelled"] = m.cancelled;
  if (m.readings.empty()) return j;
  const ColourReading& best = m.best_reading();
  j["achieved"] = {{"lab", lab(best.lab)}};
  j["delta_e00"] = best.delta_e00;
  j["dye_scale"] = nlohmann::json::array();
  for (size_t d = 0; d < m.basis.names.size(); ++d) {
    const double initial = m.basis.initial_scale[d];
    j["dye_scale"].push_back({{"dye", m.basis.names[d]},
                              {"scale", best.scale[d]},
                              {"of_recipe", initial > 0 ? nlohmann::json(best.scale[d] / initial)
                                                        : nlohmann::json(nullptr)}});
  }
  double cpu = 0;
  j["readings"] = nlohmann::json::array();
  for (const ColourReading& r : m.readings) {
    cpu += r.cpu_seconds;
    j["readings"].push_back({{"scale", r.scale},
                             {"lab", lab(r.lab)},
                             {"delta_e00", r.delta_e00},
                             {"cpu_seconds", r.cpu_seconds}});
  }
  j["iterations"] = m.readings.size();
  j["cpu_seconds"] = cpu;
  return j;
}

}  // namespace weft
