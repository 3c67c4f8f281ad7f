#include "weft/fabric/fiber_sampler.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace weft {
namespace {

// A bound of |cos theta| over cell b (for rejection): its largest value on a lattice that includes
// the edges, a little enlarged; the pole's cell reaches 1.
double max_cos_in(const DirectionGrid& grid, int b) {
  double m = 0;
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j)
      m = std::max(
          m, std::abs(DirectionGrid::to_direction(grid.chart_point(b, i / 16.0, j / 16.0)).z));
  return std::min(1.0, 1.02 * m + 1e-6);
}

}  // namespace

FiberSampler::FiberSampler(const TabulatedBsdfTable& t) : table(&t), grid(t.grid()) {
  const int bins = grid.bins(), nc = t.channels;
  group_size = (nc + kChannelGroups - 1) / kChannelGroups;
  groups = (nc + group_size - 1) / group_size;
  strategies = groups + 1;
  areas = grid.cosine_weighted_areas();
  max_cos.resize(bins);
  for (int b = 0; b < bins; ++b) max_cos[b] = max_cos_in(grid, b);
  albedo.assign(static_cast<size_t>(bins) * strategies, 0.0);
  rows.resize(static_cast<size_t>(bins) * strategies);
  std::vector<double> w(static_cast<size_t>(strategies) * bins);
  for (int i = 0; i < bins; ++i) {
    for (int o = 0; o < bins; ++o)
      for (int s = 0; s < strategies; ++s)
        w[static_cast<size_t>(s) * bins + o] = value(i, o, s) * areas[o];
    for (int s = 0; s < strategies; ++s) {
      const std::span<const double> ws(w.data() + static_cast<size_t>(s) * bins, bins);
      for (double x : ws) albedo[static_cast<size_t>(i) * strategies + s] += x;
      rows[static_cast<size_t>(i) * strategies + s] = Distribution1D(ws);
    }
  }
}

FiberSampler::FiberSampler(const TabulatedBsdfTable& rest, const SurfaceLobe& l,
                           const std::vector<double>& lobe_cells)
    : FiberSampler(rest) {
  lobe = &l;
  const int bins = grid.bins(), nc = rest.channels;
  const size_t per_bin = static_cast<size_t>(nc);
  rest_albedo_c.assign(static_cast<size_t>(bins) * per_bin, 0.0);
  lobe_albedo_c.assign(static_cast<size_t>(bins) * per_bin, 0.0);
  for (int i = 0; i < bins; ++i)
    for (int o = 0; o < bins; ++o)
      for (int c = 0; c < nc; ++c) {
        const size_t k = static_cast<size_t>(i) * per_bin + static_cast<size_t>(c);
        rest_albedo_c[k] += rest.at(i, o, c) * areas[o];
        lobe_albedo_c[k] +=
            lobe_cells[(static_cast<size_t>(i) * bins + o) * per_bin + static_cast<size_t>(c)] *
            areas[o];
      }
  lobe_albedo.assign(static_cast<size_t>(bins) * strategies, 0.0);
  for (int i = 0; i < bins; ++i)
    for (int s = 0; s < strategies; ++s)
      lobe_albedo[static_cast<size_t>(i) * strategies + s] =
          group_mean({lobe_albedo_c.data() + static_cast<size_t>(i) * per_bin, per_bin}, s);
  const SurfaceLobe::DistinctIndices indices = l.distinct_indices();
  for (double n : indices.ior)
    lobe_albedo_tables.emplace_back(l.distribution.model, l.distribution.alpha, n);
  albedo_table_of_channel = indices.of_channel;
}

double FiberSampler::group_mean(std::span<const double> x, int s) const {
  const int first = first_channel(s), last = last_channel(s);
  double mean = 0;
  for (int c = first; c < last; ++c) mean += x[static_cast<size_t>(c)];
  return mean / (last - first);
}

void FiberSampler::exact_lobe_split(int bin, const Vec3& wi, std::span<double> rho,
                                    std::span<double> k) const {
  const size_t nc = rho.size(), base = static_cast<size_t>(bin) * nc;
  for (size_t c = 0; c < nc; ++c) {
    rho[c] =
        wi.z > 0 ? lobe_albedo_tables[static_cast<size_t>(albedo_table_of_channel[c])](wi.z) : 0.0;
    const double a = rest_albedo_c[base + c], l = lobe_albedo_c[base + c];
    k[c] = a > 0 ? std::max(0.0, a + l - rho[c]) / a : 0.0;
  }
}

int FiberSampler::last_channel(int s) const {
  return s < groups ? std::min(table->channels, (s + 1) * group_size) : table->channels;
}

double FiberSampler::value(int i, int o, int s) const {
  const int first = first_channel(s), last = last_channel(s);
  if (last - first == 1) return table->at(i, o, first);
  double mean = 0;
  for (int c = first; c < last; ++c) mean += table->at(i, o, c);
  return mean / (last - first);
}

Vec3 FiberSampler::cosine_direction_in(int b, Rng& rng) const {
  for (int tries = 0; tries < 1000; ++tries) {
    const Vec3 d = DirectionGrid::to_direction(grid.chart_point(b, rng.uniform(), rng.uniform()));
    if (rng.uniform() * max_cos[b] <= std::abs(d.z)) return d;
  }
  return grid.bin_center(b);  // a cell of vanishing cosine mass: never drawn in practice
}

}  // namespace weft
