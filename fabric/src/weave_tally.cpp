// The weave tally of the fiber-level ray trace: exits by position within the repeat, at a coarse
// angular resolution (weave_tally.h), and the weave table made from them.
#include "weft/fabric/weave_tally.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "weft/core/error.h"

namespace weft {
namespace {

// Per coarse bin, the sum of the cosine-weighted areas of the fine bins it holds.
std::vector<double> coarse_areas(const DirectionGrid& fine, const std::vector<int>& coarse_of,
                                 int coarse_bins) {
  const std::vector<double> d = fine.cosine_weighted_areas();
  std::vector<double> a(coarse_bins, 0.0);
  for (int b = 0; b < fine.bins(); ++b) a[coarse_of[b]] += d[b];
  return a;
}

}  // namespace

void validate_weave_options(const FabricRaytraceOptions& o) {
  const int u = o.weave_positions_u, v = o.weave_positions_v;
  if (u == 0 && v == 0) return;
  const std::string range =
      "must lie in [1, " + std::to_string(WeaveTable::kMaxPositions) + "] (both 0: no weave table)";
  if (u < 1 || u > WeaveTable::kMaxPositions) throw Error("", "weave_positions_u", range);
  if (v < 1 || v > WeaveTable::kMaxPositions) throw Error("", "weave_positions_v", range);
  if (o.weave_resolution < 1 || o.weave_resolution > o.resolution)
    throw Error("", "weave_resolution",
                "must lie in [1, the table's resolution " + std::to_string(o.resolution) + "]");
}

std::vector<int> coarse_bins_of(const DirectionGrid& fine, const DirectionGrid& coarse) {
  std::vector<int> out(fine.bins());
  for (int b = 0; b < fine.bins(); ++b) out[b] = coarse.bin_of_chart(fine.chart_point(b, 0.5, 0.5));
  return out;
}

std::vector<double> coarse_table_average(const TabulatedBsdfTable& t, int coarse_resolution) {
  const DirectionGrid fine = t.grid(), coarse{coarse_resolution};
  const std::vector<int> of = coarse_bins_of(fine, coarse);
  const std::vector<double> d = fine.cosine_weighted_areas();
  const std::vector<double> area = coarse_areas(fine, of, coarse.bins());
  const int nb = fine.bins(), cb = coarse.bins(), nc = t.channels;
  std::vector<double> out(static_cast<size_t>(cb) * cb * nc, 0.0);
  for (int a = 0; a < nb; ++a)
    for (int b = 0; b < nb; ++b)
      for (int c = 0; c < nc; ++c)
        out[(static_cast<size_t>(of[a]) * cb + of[b]) * nc + c] += t.at(a, b, c) * d[a] * d[b];
  for (int i = 0; i < cb; ++i)
    for (int o = 0; o < cb; ++o)
      for (int c = 0; c < nc; ++c)
        out[(static_cast<size_t>(i) * cb + o) * nc + c] /= area[i] * area[o];
  return out;
}

double weave_tally_bytes(int table_resolution, int weave_resolution, int positions_u,
                         int positions_v, int channels) {
  if (positions_u <= 0) return 0;
  const double fine = DirectionGrid{table_resolution}.bins();
  const double coarse = DirectionGrid{weave_resolution}.bins();
  const double per_bin = static_cast<double>(positions_u) * positions_v * coarse * channels;
  // During the trace the sums and squares per fine bin, and as many for the computed
  // straight-through light's part; the bins' books and a part file's copy of them; the booked
  // values, the modulation (floats) and its copy for the writer.
  const double sums = 4 * fine * per_bin * sizeof(double);
  const double books = 2 * fine * per_bin * sizeof(double);
  const double table = per_bin * coarse * (sizeof(double) + 2 * sizeof(float));
  return sums + books + table;
}

void weave_totals(const WeaveShape& shape, FabricRaytraceResult& r) {
  if (!shape.on()) return;
  const DirectionGrid fine = r.table.grid(), coarse{shape.resolution};
  const std::vector<int> of = coarse_bins_of(fine, coarse);
  const std::vector<double> area = coarse_areas(fine, of, coarse.bins());
  const int cb = coarse.bins(), nc = r.table.channels, np = shape.positions();
  const size_t per_bin = static_cast<size_t>(np) * cb * nc;
  WeaveTable& w = r.weave;
  w.resolution = shape.resolution;
  w.channels = nc;
  w.positions_u = shape.positions_u, w.positions_v = shape.positions_v;
  w.repeat_u_m = shape.repeat_u_m, w.repeat_v_m = shape.repeat_v_m;
  // The booked values B[pos][wi][wo][c], each incident bin's part added in bin order.
  std::vector<double> booked(static_cast<size_t>(np) * cb * cb * nc, 0.0);
  std::vector<double> noise2(nc, 0.0);
  for (size_t a = 0; a < r.bin_books.size(); ++a) {
    const FabricBinBooks& b = r.bin_books[a];
    if (b.weave_values.size() != per_bin || b.weave_noise2.size() != static_cast<size_t>(nc))
      throw Error("", "weave", "incident bin " + std::to_string(a) + " has no weave books");
    const size_t i = static_cast<size_t>(of[a]);
    for (int p = 0; p < np; ++p)
      for (int o = 0; o < cb; ++o)
        for (int c = 0; c < nc; ++c)
          booked[w.index(p, static_cast<int>(i), o, c)] +=
              b.weave_values[(static_cast<size_t>(p) * cb + o) * nc + c];
    for (int c = 0; c < nc; ++c) noise2[c] += b.weave_noise2[c];
  }
  r.weave_mean.assign(static_cast<size_t>(cb) * cb * nc, 0.0);
  for (int p = 0; p < np; ++p)
    for (size_t k = 0; k < r.weave_mean.size(); ++k)
      r.weave_mean[k] += booked[p * r.weave_mean.size() + k];
  for (double& m : r.weave_mean) m /= np;
  w.modulation.assign(booked.size(), 1.0f);
  double all_noise2 = 0, all_signal2 = 0;
  for (int p = 0; p < np; ++p)
    for (int i = 0; i < cb; ++i)
      for (int o = 0; o < cb; ++o)
        for (int c = 0; c < nc; ++c) {
          const size_t v = w.index(p, i, o, c);
          const double mean = r.weave_mean[(static_cast<size_t>(i) * cb + o) * nc + c];
          if (mean > 0) w.modulation[v] = static_cast<float>(booked[v] / mean);
          all_signal2 += booked[v] * booked[v] * area[i] * area[o];
        }
  for (double x : noise2) all_noise2 += x;
  r.weave_relative_noise = all_signal2 > 0 ? std::sqrt(all_noise2 / all_signal2) : 0.0;
  describe_weave(r.table, w);
}

void describe_weave(const TabulatedBsdfTable& table, WeaveTable& weave) {
  weave.metadata.clear();
  for (const auto& [key, value] : table.metadata)
    if (!WeaveTable::is_reserved_attribute(key)) weave.metadata[key] = value;
  weave.metadata["fabric_checksum"] = table.checksum();
}

namespace raytrace {

size_t WeaveLayout::per_bin() const {
  return static_cast<size_t>(shape.positions()) * coarse_bins * channels;
}

WeaveLayout weave_layout(const FabricRaytraceOptions& o, int channels, double x0, double z0,
                         double px, double pz, double y0, double y1) {
  WeaveLayout w;
  w.shape = {o.weave_positions_u, o.weave_positions_v, o.weave_resolution, px, pz};
  const double values = static_cast<double>(w.shape.positions()) *
                        std::pow(DirectionGrid{o.weave_resolution}.bins(), 2) * channels;
  if (values > static_cast<double>(WeaveTable::kMaxValues))
    throw Error("", "weave_positions",
                "a weave table of " + std::to_string(w.shape.positions()) + " positions at " +
                    "resolution " + std::to_string(o.weave_resolution) + " would hold more than " +
                    std::to_string(WeaveTable::kMaxValues) + " values: fewer positions or a " +
                    "coarser weave_resolution");
  w.channels = channels;
  w.table_resolution = o.resolution;
  const DirectionGrid fine{o.resolution}, coarse{o.weave_resolution};
  w.fine_bins = fine.bins();
  w.coarse_bins = coarse.bins();
  w.coarse_of_fine = coarse_bins_of(fine, coarse);
  w.x0 = x0, w.z0 = z0, w.px = px, w.pz = pz, w.y_mid = 0.5 * (y0 + y1);
  return w;
}

int weave_position(const WeaveLayout& w, const Vec3& p, const Vec3& d) {
  // An exit leaves the slab through a face, so d.y is not 0.
  const double t = (w.y_mid - p.y) / d.y;
  const double fu = (p.x + t * d.x - w.x0) / w.px;
  const double fv = (w.z0 + w.pz - (p.z + t * d.z)) / w.pz;
  auto cell = [](double f, int n) {
    const int k = static_cast<int>(std::floor((f - std::floor(f)) * n));
    return std::clamp(k, 0, n - 1);  // f - floor(f) rounds up to 1 for tiny negative f
  };
  return cell(fv, w.shape.positions_v) * w.shape.positions_u + cell(fu, w.shape.positions_u);
}

void tally_weave_exit(const WeaveLayout& w, WeaveExits& tally, uint64_t unit, int bin, int exit_bin,
                      const Vec3& p, const Vec3& d, std::span<const double> weights) {
  const uint64_t cell = (static_cast<uint64_t>(bin) * static_cast<uint64_t>(w.shape.positions()) +
                         static_cast<uint64_t>(weave_position(w, p, d))) *
                            static_cast<uint64_t>(w.coarse_bins) +
                        static_cast<uint64_t>(w.coarse_of_fine[exit_bin]);
  // The unit's exits are the last ones in the list.
  for (size_t e = tally.exits.size(); e > 0 && tally.exits[e - 1].unit == unit; --e)
    if (tally.exits[e - 1].cell == cell) {
      for (size_t c = 0; c < weights.size(); ++c)
        tally.weights[tally.exits[e - 1].first + c] += weights[c];
      return;
    }
  tally.exits.push_back({cell, unit, static_cast<uint32_t>(tally.weights.size())});
  tally.weights.insert(tally.weights.end(), weights.begin(), weights.end());
}

WeaveSums weave_sums_for(const WeaveLayout& w) {
  const size_t n = static_cast<size_t>(w.fine_bins) * w.per_bin();
  return {std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
}

void add_weave_task(const WeaveLayout& w, const WeaveExits& tally, WeaveSums& sums) {
  const size_t nc = static_cast<size_t>(w.channels);
  for (const WeaveExit& e : tally.exits) {
    const size_t at = e.cell * nc;
    for (size_t c = 0; c < nc; ++c) {
      const double x = tally.weights[e.first + c];
      sums.sum[at + c] += x;
      sums.sum2[at + c] += x * x;
    }
  }
}

void weave_bin_books(const WeaveLayout& w, const WeaveSums& sums, const WeaveSums& exact,
                     uint64_t per_bin, const std::vector<uint64_t>& units,
                     FabricRaytraceResult& result) {
  const DirectionGrid fine{w.table_resolution};
  const std::vector<double> area = coarse_areas(fine, w.coarse_of_fine, w.coarse_bins);
  const int np = w.shape.positions(), cb = w.coarse_bins, nc = w.channels;
  const double n = static_cast<double>(per_bin);
  // B = positions x the exits' weights through the cell over the power that fell on it, as a
  // cosine-weighted average over the coarse cell pair: its mean over the positions is the table's
  // coarse average (tabulate's scale over the coarse cells).
  const double omega = fine.bin_solid_angle() * np;
  for (int a = 0; a < w.fine_bins; ++a) {
    FabricBinBooks& b = result.bin_books[a];
    b.weave_values.assign(w.per_bin(), 0.0);
    b.weave_noise2.assign(nc, 0.0);
    const double u = static_cast<double>(units[a]);
    const double area_i = area[w.coarse_of_fine[a]];
    for (int p = 0; p < np; ++p)
      for (int o = 0; o < cb; ++o) {
        const double scale = omega / (n * area_i * area[o]);
        for (int c = 0; c < nc; ++c) {
          const size_t k = (static_cast<size_t>(p) * cb + o) * nc + c;
          const size_t v = static_cast<size_t>(a) * w.per_bin() + k;
          const double m1 = sums.sum[v] / u;
          const double se = std::sqrt(std::max(0.0, sums.sum2[v] / u - m1 * m1) / u) * u * scale;
          const bool computed = !exact.sum.empty();
          b.weave_values[k] = (sums.sum[v] + (computed ? exact.sum[v] : 0.0)) * scale;
          // The computed part's variance, independent of the particles' (its own streams).
          const double se2 = se * se + (computed ? exact.sum2[v] * scale * scale : 0.0);
          b.weave_noise2[c] += se2 * area_i * area[o];
        }
      }
  }
}

}  // namespace raytrace
}  // namespace weft
