#include "weft/bench/sheen_bench.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <optional>
#include <set>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/table_reader.h"

namespace weft {
namespace {

Vec3 inplane(double theta_deg, double azimuth_deg, bool mirror) {
  const double t = deg_to_rad(theta_deg), p = deg_to_rad(azimuth_deg), s = mirror ? -1 : 1;
  return {s * std::sin(t) * std::cos(p), s * std::sin(t) * std::sin(p), std::cos(t)};
}

// A table as a reader that knows its sheen takes it (TableReader: the rest, made once per table
// and only with a sheen, interpolated, plus the sheen).
double beta_at(const TableReader& t, double theta_i, double azimuth, double view) {
  const size_t nc = static_cast<size_t>(t.channels());
  std::vector<double> f(nc);
  t.eval(inplane(view, azimuth, true), inplane(theta_i, azimuth, false), f);
  double mean = 0;
  for (size_t c = 0; c < nc; ++c) mean += f[c];
  return kPi * mean / static_cast<double>(nc);
}

void check_angles(const std::vector<double>& angles, double lo, double hi, const char* field) {
  if (angles.empty()) throw Error("", field, "needs at least one angle");
  for (double a : angles)
    if (!(a >= lo && a <= hi))
      throw Error("", field,
                  "angle " + std::to_string(a) + " is outside [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "] degrees");
}

// The narrow reference's options, each named as the command line names it; the light's own
// checks (FabricRaytraceOptions::validate) follow per case.
void check_narrow(const SheenRequest& r) {
  if (r.reference == SheenReference::grid) {
    if (!r.narrow_reference.empty())
      throw Error("", "--narrow-reference", "is read with --reference-light narrow");
    return;
  }
  if (!r.reference_batches.empty())
    throw Error("", "--reference", "reads a grid reference's batches, not a narrow one's");
  if (r.narrow_particles < 1 || r.narrow_particles > (uint64_t{1} << 32))
    throw Error("", "--narrow-particles", "must lie in [1, 2^32]");
  if (r.narrow_next_event_rays < 0 || r.narrow_next_event_rays > kMaxNextEventRays)
    throw Error("", "--nee", "must lie in [0, " + std::to_string(kMaxNextEventRays) + "]");
  const auto check = [](double x, double lo, double hi, const char* option) {
    if (!(x >= lo && x <= hi))
      throw Error(
          "", option,
          "must lie in [" + ParamReader::fmt(lo) + ", " + ParamReader::fmt(hi) + "] degrees");
  };
  check(r.narrow.half_angle_deg, 0, NarrowLight::kMaxHalfAngleDeg, "--cone");
  check(r.narrow.band_deg, NarrowLight::kMinBandDeg, NarrowLight::kMaxBandDeg, "--band");
  check(r.narrow.bin_deg, NarrowLight::kMinBinDeg, NarrowLight::kMaxBinDeg, "--bin");
  if (!(r.smooth_deg >= 0 && r.smooth_deg <= 10))
    throw Error("", "--smooth", "must lie in [0, 10] degrees");
}

// The peak of a curve beta over ascending views a step apart, with its base given.
InplanePeak peak_of_curve(const std::vector<double>& views, const std::vector<double>& beta,
                          double theta_i, double base, double step) {
  InplanePeak p;
  size_t k = views.size();
  for (size_t i = 0; i < views.size(); ++i)
    if (std::abs(views[i] - theta_i) <= 10 && (k == views.size() || beta[i] > beta[k])) k = i;
  p.beta = beta[k], p.view_deg = views[k];
  p.base = base;
  const double half = p.base + 0.5 * (p.beta - p.base);
  size_t a = k, b = k;
  while (a > 0 && beta[a - 1] > half) --a;
  while (b + 1 < beta.size() && beta[b + 1] > half) ++b;
  p.fwhm_deg = views[b] - views[a] + step;
  return p;
}

// The narrow reference's plan: its curves read (each asked case must be in the file), or the
// sample its lights are traced on; no rows either way.
SheenPlan plan_narrow(SheenPlan p) {
  const SheenRequest& r = p.request;
  if (r.narrow_reference.empty()) {
    p.sample = make_woven_sample(read_weave_options(r.weave));
    return p;
  }
  p.narrow_cases = read_narrow_reference(r.narrow_reference, p.request, p.fiber);
  for (double phi : r.azimuths_deg)
    for (double ti : r.incidences_deg) {
      bool found = false;
      for (const NarrowCase& k : p.narrow_cases)
        found = found || (k.incidence_deg == ti && k.azimuth_deg == phi);
      if (!found)
        throw Error(r.narrow_reference, "cases",
                    "holds no case at incidence " + ParamReader::fmt(ti) + ", azimuth " +
                        ParamReader::fmt(phi) + " (--incidence, --azimuth)");
    }
  return p;
}

InplanePeak peak_of(const TableReader& t, double theta_i, double azimuth) {
  std::vector<double> views, beta;
  for (double v = 0; v <= 89.0; v += 0.5)
    views.push_back(v), beta.push_back(beta_at(t, theta_i, azimuth, v));
  const double base = std::min(beta_at(t, theta_i, azimuth, std::max(0.0, theta_i - 20)),
                               beta_at(t, theta_i, azimuth, std::min(89.0, theta_i + 20)));
  InplanePeak p = peak_of_curve(views, beta, theta_i, base, 0.5);
  p.mirror_beta = beta_at(t, theta_i, azimuth, theta_i);
  return p;
}

// A narrow light's curve on the mirror's side (its plane bins of theta' < 0, views ascending):
// beta = pi f, the channels' mean, and as its standard error the channels' mean of theirs (an
// upper bound: the channels share their particles).
InplaneCurve mirror_curve(const FabricRaytraceResult& t, const NarrowLight& n, int nc) {
  InplaneCurve c;
  for (int k = n.plane_bins() - 1; k >= 0; --k) {
    const double view = mirror_view_deg(n, k);
    if (!(view > 0)) continue;
    double f = 0, se = 0;
    for (int ch = 0; ch < nc; ++ch) {
      f += t.plane_f[static_cast<size_t>(k) * nc + ch];
      se += t.plane_f_se[static_cast<size_t>(k) * nc + ch];
    }
    c.view_deg.push_back(view);
    c.beta.push_back(kPi * f / nc);
    c.beta_se.push_back(kPi * se / nc);
  }
  return c;
}

// A narrow curve's peak: its running mean over the bins within smooth_deg / 2 of each, read as
// a table's curve is, its base the smoothed curve at the views nearest theta_i -+ 20 degrees.
InplanePeak narrow_peak(const InplaneCurve& c, double theta_i, double smooth_deg, double step) {
  const int m = static_cast<int>(std::floor(smooth_deg / 2 / step + 1e-9));
  const int n = static_cast<int>(c.beta.size());
  std::vector<double> smooth(c.beta.size());
  for (int i = 0; i < n; ++i) {
    double s = 0;
    int count = 0;
    for (int j = std::max(0, i - m); j <= std::min(n - 1, i + m); ++j) s += c.beta[j], ++count;
    smooth[i] = s / count;
  }
  const auto at = [&](double view) {
    size_t best = 0;
    for (size_t i = 1; i < c.view_deg.size(); ++i)
      if (std::abs(c.view_deg[i] - view) < std::abs(c.view_deg[best] - view)) best = i;
    return smooth[best];
  };
  InplanePeak p = peak_of_curve(c.view_deg, smooth, theta_i,
                                std::min(at(theta_i - 20), at(theta_i + 20)), step);
  p.mirror_beta = at(theta_i);
  return p;
}

// The standard error of a mean over n values from their sum and sum of squares.
double standard_error(double s, double s2, double n) {
  const double mean = s / n;
  return std::sqrt(std::max(0.0, s2 / n - mean * mean) / (n - 1));
}

// A case of the narrow reference from its batches' curves: their mean (each bin's error
// combined), its peak read after the running mean, and the peak's standard error over the batches.
SheenCase narrow_case(double ti, double phi, std::vector<InplaneCurve> batches,
                      const SheenRequest& r) {
  SheenCase c{ti, phi, {}, 0, 0, {}, {}, {}};
  const size_t n = batches[0].beta.size();
  const double count = static_cast<double>(batches.size());
  InplaneCurve& mean = c.reference_curve;
  mean = {batches[0].view_deg, std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
  double s = 0, s2 = 0, m = 0, m2 = 0;  // the batches' peaks and mirror readings
  for (const InplaneCurve& b : batches) {
    const InplanePeak peak = narrow_peak(b, ti, r.smooth_deg, r.narrow.bin_deg);
    s += peak.beta, s2 += peak.beta * peak.beta;
    m += peak.mirror_beta, m2 += peak.mirror_beta * peak.mirror_beta;
    for (size_t i = 0; i < n; ++i) {
      mean.beta[i] += b.beta[i] / count;
      mean.beta_se[i] += b.beta_se[i] * b.beta_se[i];
    }
  }
  for (double& se : mean.beta_se) se = std::sqrt(se) / count;
  c.reference = narrow_peak(mean, ti, r.smooth_deg, r.narrow.bin_deg);
  c.reference_beta_se = standard_error(s, s2, count);
  c.reference_mirror_se = standard_error(m, m2, count);
  c.reference_batches = std::move(batches);
  return c;
}

// Batch b of a case traced: its light at (ti, phi) on seed + b. Nothing when cancelled.
std::optional<InplaneCurve> trace_narrow(const SheenPlan& p, double ti, double phi, int b,
                                         const ProgressCallback& progress) {
  const SheenRequest& r = p.request;
  FabricRaytraceOptions o;
  o.resolution = 1;  // the table's row is not read, and R 1's is the cheapest to keep
  o.particles_per_bin = r.narrow_particles;
  o.seed = r.seed + static_cast<uint64_t>(b);
  o.threads = r.threads;
  o.straight_through = StraightThrough::sampled;
  o.next_event_rays = r.narrow_next_event_rays;
  o.narrow_light = r.narrow;
  o.narrow_light->theta_deg = ti, o.narrow_light->azimuth_deg = phi;
  const FabricRaytraceResult t = raytrace_fabric_table(p.sample, p.fiber, o, progress);
  if (t.cancelled) return std::nullopt;
  return mirror_curve(t, r.narrow, p.fiber.channels);
}

// The narrow reference: per case, each batch's light traced on its own (seeds seed, seed + 1,
// ...), or its curves read.
SheenResult run_narrow(const SheenPlan& p, const ProgressCallback& progress) {
  const SheenRequest& r = p.request;
  SheenResult out;
  const std::clock_t cpu0 = std::clock();  // the process's CPU time, all threads
  const uint64_t n = r.narrow_particles, total = p.narrow_cases.empty()
                                                     ? static_cast<uint64_t>(r.batches) *
                                                           r.incidences_deg.size() *
                                                           r.azimuths_deg.size()
                                                     : 0;
  uint64_t done = 0;
  // In particles: at R 1 a light from above is bin 0, the batch's first n particles.
  const ProgressCallback per_batch = [&](const ProgressUpdate& u) {
    const uint64_t in_batch = u.stage == "particles" ? std::min(n, u.done) : 0;
    return progress({"reference particles", done * n + in_batch, total * n});
  };
  std::vector<TableReader> readers;
  for (const auto& t : p.tables) readers.emplace_back(t, r.threads);
  for (double phi : r.azimuths_deg)
    for (double ti : r.incidences_deg) {
      std::vector<InplaneCurve> batches;
      for (const NarrowCase& k : p.narrow_cases)
        if (k.incidence_deg == ti && k.azimuth_deg == phi) batches = k.batches;
      for (int b = 0; b < r.batches && p.narrow_cases.empty(); ++b) {
        std::optional<InplaneCurve> curve = trace_narrow(p, ti, phi, b, per_batch);
        if (!curve || !progress({"reference particles", ++done * n, total * n})) {
          out.cancelled = true;
          return out;
        }
        batches.push_back(std::move(*curve));
      }
      SheenCase c = narrow_case(ti, phi, std::move(batches), r);
      for (const TableReader& t : readers) c.tables.push_back(peak_of(t, ti, phi));
      out.cases.push_back(std::move(c));
    }
  out.cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  return out;
}

}  // namespace

double mirror_view_deg(const NarrowLight& light, int k) {
  return -light.plane_angle_deg(k);
}

std::vector<double> narrow_views_deg(const NarrowLight& light) {
  std::vector<double> views;
  for (int k = light.plane_bins() - 1; k >= 0; --k)
    if (mirror_view_deg(light, k) > 0) views.push_back(mirror_view_deg(light, k));
  return views;
}

InplanePeak inplane_peak(const TabulatedBsdfTable& table, double theta_i, double azimuth) {
  return peak_of(TableReader(table), theta_i, azimuth);
}

SheenPlan plan_sheen(const SheenRequest& r) {
  SheenPlan p;
  p.request = r;
  if (r.resolution < 2 || r.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "--resolution", "must lie in [2, 32]");
  if (r.particles_per_bin < 1 || r.particles_per_bin > (uint64_t{1} << 32))
    throw Error("", "--particles", "must lie in [1, 2^32]");
  if (r.batches < 2 || r.batches > 64)
    throw Error("", "--batches", "must lie in [2, 64] (the peak's uncertainty needs two)");
  // Up to 85 degrees: the peak is searched up to the 89 degree view, and the satin's grazing
  // light is where tables and reference part most.
  check_angles(r.incidences_deg, 10, 85, "--incidence");
  check_angles(r.azimuths_deg, 0, 360, "--azimuth");
  check_narrow(r);
  if (r.fiber.empty()) throw Error("", "--fiber", "a fiber table (.exr) is required");
  p.fiber = TabulatedBsdfTable::read_exr(r.fiber);
  if (p.fiber.kind != "fiber") throw Error(r.fiber, "kind", "must be a fiber table");
  for (const std::string& f : r.tables) {
    p.tables.push_back(TabulatedBsdfTable::read_exr(f));
    if (p.tables.back().kind != "fabric") throw Error(f, "kind", "must be a fabric table");
  }
  for (const std::string& f : r.reference_batches) {
    p.reference_batches.push_back(TabulatedBsdfTable::read_exr(f));
    const TabulatedBsdfTable& b = p.reference_batches.back();
    if (b.kind != "fabric") throw Error(f, "kind", "must be a fabric table (a reference batch)");
    if (b.resolution != p.reference_batches[0].resolution || b.channels != p.fiber.channels)
      throw Error(f, "resolution",
                  "a reference batch must share the first batch's grid and the fiber's channels");
  }
  if (r.reference_batches.size() == 1)
    throw Error(r.reference_batches[0], "--reference",
                "needs two or more batches (the peak's uncertainty)");
  if (r.reference == SheenReference::narrow) return plan_narrow(std::move(p));
  if (!p.reference_batches.empty()) {
    p.request.resolution = p.reference_batches[0].resolution;
    p.request.batches = static_cast<int>(p.reference_batches.size());
    return p;  // nothing to trace
  }
  p.sample = make_woven_sample(read_weave_options(r.weave));
  const DirectionGrid g{r.resolution};
  std::set<int> rows;
  for (double phi : r.azimuths_deg)
    for (double ti : r.incidences_deg) {
      const auto fp = g.bilinear(DirectionGrid::to_chart(inplane(ti, phi, false)));
      for (int k = 0; k < 4; ++k)
        if (fp.weight[k] > 0) rows.insert(fp.bin[k]);
    }
  p.rows.assign(rows.begin(), rows.end());
  return p;
}

SheenResult run_sheen(const SheenPlan& p, const ProgressCallback& progress) {
  if (p.request.reference == SheenReference::narrow) return run_narrow(p, progress);
  const SheenRequest& r = p.request;
  SheenResult out;
  const std::clock_t cpu0 = std::clock();  // the process's CPU time, all threads
  std::vector<TabulatedBsdfTable> batch_tables = p.reference_batches;
  const uint64_t total = static_cast<uint64_t>(r.batches) * p.rows.size();
  uint64_t done = 0;
  // One stage, rows: a row's own stages (scene build, particles) only ask whether to go on.
  const ProgressCallback per_row = [&](const ProgressUpdate&) {
    return progress({"reference rows", done, total});
  };
  for (int b = 0; b < r.batches && p.reference_batches.empty(); ++b) {
    TabulatedBsdfTable sum;
    for (int row : p.rows) {
      FabricRaytraceOptions o;
      o.resolution = r.resolution;
      o.particles_per_bin = r.particles_per_bin;
      o.seed = r.seed + static_cast<uint64_t>(b);
      o.threads = r.threads;
      o.first_bin = row, o.bin_count = 1;
      const FabricRaytraceResult t = raytrace_fabric_table(p.sample, p.fiber, o, per_row);
      if (t.cancelled || !progress({"reference rows", ++done, total})) {
        out.cancelled = true;
        return out;
      }
      // Each row has a whole run's bits; the others are zero.
      if (sum.values.empty())
        sum = t.table;
      else
        for (size_t k = 0; k < sum.values.size(); ++k) sum.values[k] += t.table.values[k];
    }
    batch_tables.push_back(std::move(sum));
  }
  out.reference = batch_tables[0];
  for (size_t k = 0; k < out.reference.values.size(); ++k) {
    double mean = 0;
    for (const auto& t : batch_tables) mean += t.values[k];
    out.reference.values[k] = static_cast<float>(mean / r.batches);
  }
  out.batches = batch_tables;
  std::vector<TableReader> readers;
  for (const auto& t : p.tables) readers.emplace_back(t, r.threads);
  for (double phi : r.azimuths_deg)
    for (double ti : r.incidences_deg) {
      SheenCase c{ti, phi, inplane_peak(out.reference, ti, phi), 0, 0, {}, {}, {}};
      double s = 0, s2 = 0, m = 0, m2 = 0;
      for (const auto& t : batch_tables) {
        const InplanePeak v = inplane_peak(t, ti, phi);
        s += v.beta, s2 += v.beta * v.beta, m += v.mirror_beta, m2 += v.mirror_beta * v.mirror_beta;
      }
      c.reference_beta_se = standard_error(s, s2, r.batches);
      c.reference_mirror_se = standard_error(m, m2, r.batches);
      for (const TableReader& t : readers) c.tables.push_back(peak_of(t, ti, phi));
      out.cases.push_back(c);
    }
  out.cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  return out;
}

}  // namespace weft
