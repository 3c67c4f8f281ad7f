#include "weft/materials/bsdf_table.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <set>
#include <utility>

#include "exr_io.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"

namespace weft {

std::vector<double> TabulatedBsdfTable::averages_from_weighted_sums(
    int resolution, const std::vector<double>& weighted_sums) {
  const DirectionGrid grid{resolution};
  const size_t cells = static_cast<size_t>(grid.bins());
  if (weighted_sums.size() != cells * cells)
    throw Error("", "weighted_sums",
                "holds " + std::to_string(weighted_sums.size()) + " values, expected " +
                    std::to_string(cells * cells));
  const auto d = grid.cosine_weighted_areas();
  std::vector<double> out(weighted_sums.size());
  for (size_t i = 0; i < cells; ++i)
    for (size_t o = 0; o < cells; ++o)
      out[i * cells + o] = weighted_sums[i * cells + o] / (d[i] * d[o]);
  return out;
}

namespace {

// The table's cells less an analytic part's cell averages ('what' names it in the message): the
// rest of f. Differences below float rounding become 0; more is an Error naming the cell.
void subtract_cells(TabulatedBsdfTable& t, const std::vector<double>& part, const std::string& file,
                    const std::string& what, const std::string& short_name) {
  for (size_t k = 0; k < t.values.size(); ++k) {
    const double v = static_cast<double>(t.values[k]) - part[k];
    if (v < -1e-6 * part[k]) {
      const size_t cell = k / static_cast<size_t>(t.channels), b = static_cast<size_t>(t.bins());
      throw Error(file,
                  "values[wi " + std::to_string(cell / b) + "][wo " + std::to_string(cell % b) +
                      "][" + t.channel_names()[k % static_cast<size_t>(t.channels)] + "]",
                  "holds " + std::to_string(t.values[k]) + ", less than its " + what + "'s " +
                      std::to_string(part[k]) + ": the cells must include the " + short_name);
    }
    t.values[k] = static_cast<float>(std::max(0.0, v));
  }
}

void add_cells(TabulatedBsdfTable& t, const std::vector<double>& part, const char* field) {
  if (part.size() != t.values.size())
    throw Error("", field, "the part's cells do not fit the table");
  for (size_t k = 0; k < t.values.size(); ++k)
    t.values[k] = static_cast<float>(static_cast<double>(t.values[k]) + part[k]);
}

}  // namespace

TabulatedBsdfTable TabulatedBsdfTable::without_surface_lobe(const std::string& file, int threads,
                                                            std::vector<double>* lobe_cells) const {
  TabulatedBsdfTable rest = *this;
  if (!surface_lobe) return rest;
  rest.surface_lobe.reset();
  std::vector<double> lobe = surface_lobe->cell_averages(grid(), threads);
  subtract_cells(rest, lobe, file, "surface lobe", "lobe");
  if (lobe_cells) *lobe_cells = std::move(lobe);
  return rest;
}

void TabulatedBsdfTable::add_surface_lobe(const SurfaceLobe& lobe, int threads,
                                          const std::vector<double>* given) {
  if (surface_lobe) throw Error("", "surface_lobe", "the table has a surface lobe already");
  lobe.validate(channels, "");
  const std::vector<double> computed =
      given ? std::vector<double>{} : lobe.cell_averages(grid(), threads);
  add_cells(*this, given ? *given : computed, "surface_lobe");
  surface_lobe = lobe;
}

TabulatedBsdfTable TabulatedBsdfTable::without_sheen(const std::string& file, int threads,
                                                     std::vector<double>* sheen_cells) const {
  TabulatedBsdfTable rest = *this;
  if (!sheen) return rest;
  rest.sheen.reset();
  std::vector<double> part = sheen->cell_averages(threads);
  subtract_cells(rest, part, file, "sheen", "sheen");
  if (sheen_cells) *sheen_cells = std::move(part);
  return rest;
}

void TabulatedBsdfTable::add_sheen(HalfVectorLobe lobe, int threads) {
  if (sheen) throw Error("", "sheen", "the table has a sheen already");
  lobe.validate(resolution, channels, "");
  add_cells(*this, lobe.cell_averages(threads), "sheen");
  sheen = std::move(lobe);
}

void TabulatedBsdfTable::interpolate(const Vec3& wo, const Vec3& wi, std::span<double> out) const {
  std::fill(out.begin(), out.end(), 0.0);
  for_each_interpolated_cell(grid(), wo, wi, [&](int i, int o, double w) {
    for (int c = 0; c < channels; ++c) out[c] += w * static_cast<double>(at(i, o, c));
  });
}

std::string TabulatedBsdfTable::checksum() const {
  if (!sheen) return exr_io::checksum(values);
  std::vector<float> all = values;
  all.insert(all.end(), sheen->values.begin(), sheen->values.end());
  return exr_io::checksum(all);
}

std::string TabulatedBsdfTable::bands() const {
  return channels == kNumBands ? std::string(kSpectralBands) : std::string("rgb");
}

std::vector<std::string> TabulatedBsdfTable::channel_names() const {
  return exr_io::channel_names(channels);
}

namespace {

// Attribute names the format itself uses, or that OpenEXR's header reserves.
const std::set<std::string>& reserved_attribute_names() {
  static const std::set<std::string> names = {"weft_format_version",
                                              "cell_average",
                                              "parameterization",
                                              "resolution",
                                              "bands",
                                              "units",
                                              "kind",
                                              "values_fnv1a64",
                                              "channels",
                                              "compression",
                                              "dataWindow",
                                              "displayWindow",
                                              "lineOrder",
                                              "pixelAspectRatio",
                                              "screenWindowCenter",
                                              "screenWindowWidth",
                                              "tiles",
                                              "type",
                                              "name",
                                              "version",
                                              "chunkCount",
                                              "view"};
  return names;
}

}  // namespace

bool TabulatedBsdfTable::is_reserved_attribute(const std::string& name) {
  return reserved_attribute_names().count(name) > 0 || SurfaceLobe::is_attribute(name) ||
         HalfVectorLobe::is_attribute(name);
}

void TabulatedBsdfTable::validate(const std::string& file) const {
  if (resolution < 1 || resolution > kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(kMaxResolution) + "], got " +
                    std::to_string(resolution));
  if (channels != 3 && channels != kNumBands)
    throw Error(file, "bands",
                "need 3 (RGB) or 33 (390..710 nm) channels, got " + std::to_string(channels));
  if (kind != "fiber" && kind != "fabric")
    throw Error(file, "kind", "must be \"fiber\" or \"fabric\", got \"" + kind + "\"");
  const size_t expected =
      static_cast<size_t>(bins()) * static_cast<size_t>(bins()) * static_cast<size_t>(channels);
  if (values.size() != expected)
    throw Error(file, "values",
                "holds " + std::to_string(values.size()) + " numbers, expected " +
                    std::to_string(expected));
  for (const auto& [key, value] : metadata) {
    if (key.empty() || is_reserved_attribute(key))
      throw Error(file, "metadata." + key, "name is reserved by the table format");
  }
  if (surface_lobe) surface_lobe->validate(channels, file);
  if (sheen) sheen->validate(resolution, channels, file);
  for (size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (std::isfinite(v) && v >= 0) continue;
    const size_t c = i % static_cast<size_t>(channels);
    const size_t cell = i / static_cast<size_t>(channels);
    const size_t wo = cell % static_cast<size_t>(bins()), wi = cell / static_cast<size_t>(bins());
    throw Error(file,
                "values[wi " + std::to_string(wi) + "][wo " + std::to_string(wo) + "][" +
                    channel_names()[c] + "]",
                std::isfinite(v) ? "is negative (" + std::to_string(v) + ")" : "is not finite");
  }
}

TabulatedBsdfTable TabulatedBsdfTable::from_function(int resolution, int channels,
                                                     const TableFunction& f, int samples_per_cell,
                                                     uint64_t seed, int threads,
                                                     const ProgressCallback& progress) {
  const std::string who = "TabulatedBsdfTable::from_function";
  if (samples_per_cell < 1) throw Error(who, "samples_per_cell", "must be >= 1");
  TabulatedBsdfTable table;
  table.resolution = resolution;
  table.channels = channels;
  if (resolution < 1 || resolution > kMaxResolution || (channels != 3 && channels != kNumBands)) {
    table.validate(who);  // throws the precise message
  }
  const int n_bins = table.bins();
  table.values.assign(static_cast<size_t>(n_bins) * n_bins * channels, 0.0f);
  const DirectionGrid grid = table.grid();

  // Rows (wi bins) in chunks, so progress is reported from this thread between chunks.
  const int chunk = std::max(1, n_bins / 64);
  auto row = [&](uint64_t wi_task) {
    const int wi_bin = static_cast<int>(wi_task);
    const int n = samples_per_cell;
    std::vector<double> sum(channels), value(channels);
    std::array<std::vector<int>, 4> perm;
    for (auto& p : perm) p.resize(n);
    for (int wo_bin = 0; wo_bin < n_bins; ++wo_bin) {
      Rng rng(seed, static_cast<uint64_t>(wi_bin), static_cast<uint64_t>(wo_bin));
      // Latin hypercube: each of the 4 square coordinates visits each of its n strata once.
      for (auto& p : perm) {
        std::iota(p.begin(), p.end(), 0);
        for (int i = n - 1; i > 0; --i)
          std::swap(p[i], p[std::min<int>(i, static_cast<int>(rng.uniform() * (i + 1)))]);
      }
      std::fill(sum.begin(), sum.end(), 0.0);
      double weight_sum = 0;
      for (int s = 0; s < n; ++s) {
        const double ui = (perm[0][s] + rng.uniform()) / n, vi = (perm[1][s] + rng.uniform()) / n;
        const double uo = (perm[2][s] + rng.uniform()) / n, vo = (perm[3][s] + rng.uniform()) / n;
        const Vec3 wi = DirectionGrid::to_direction(grid.chart_point(wi_bin, ui, vi));
        const Vec3 wo = DirectionGrid::to_direction(grid.chart_point(wo_bin, uo, vo));
        std::fill(value.begin(), value.end(), 0.0);
        f(wo, wi, value);
        const double w = std::abs(wi.z) * std::abs(wo.z);
        weight_sum += w;
        for (int c = 0; c < channels; ++c) {
          if (!std::isfinite(value[c]) || value[c] < 0)
            throw Error(who, "f",
                        "returned a negative or non-finite value at wo bin " +
                            std::to_string(wo_bin) + ", wi bin " + std::to_string(wi_bin));
          sum[c] += value[c] * w;
        }
      }
      // Every cell has |cos| > 0 almost everywhere, so the weights cannot all vanish.
      for (int c = 0; c < channels; ++c)
        table.values[table.index(wi_bin, wo_bin, c)] =
            static_cast<float>(weight_sum > 0 ? sum[c] / weight_sum : 0.0);
    }
  };
  for (int first = 0; first < n_bins; first += chunk) {
    const int count = std::min(chunk, n_bins - first);
    parallel_for(static_cast<uint64_t>(count), threads,
                 [&](uint64_t i) { row(static_cast<uint64_t>(first) + i); });
    if (!progress({"table", static_cast<uint64_t>(first + count), static_cast<uint64_t>(n_bins)}))
      throw Error(who, "", "cancelled");
  }
  return table;
}

TabulatedBsdfTable::DirectionalAlbedo TabulatedBsdfTable::directional_albedo(int wi_bin) const {
  const DirectionGrid g = grid();
  if (wi_bin < 0 || wi_bin >= g.bins())
    throw Error(
        "", "wi_bin",
        "must lie in [0, " + std::to_string(g.bins() - 1) + "], got " + std::to_string(wi_bin));
  const auto d = g.cosine_weighted_areas();
  DirectionalAlbedo out{std::vector<double>(channels, 0.0), std::vector<double>(channels, 0.0)};
  for (int wo = 0; wo < g.bins(); ++wo) {
    // No bin straddles the horizon: an exit is on the light's side or it is not.
    auto& side = g.upper(wo) == g.upper(wi_bin) ? out.reflectance : out.transmittance;
    for (int c = 0; c < channels; ++c) side[c] += at(wi_bin, wo, c) * d[static_cast<size_t>(wo)];
  }
  return out;
}

TabulatedBsdfTable::DirectionalAlbedo TabulatedBsdfTable::directional_albedo_seen_from(
    int wo_bin) const {
  const DirectionGrid g = grid();
  if (wo_bin < 0 || wo_bin >= g.bins())
    throw Error(
        "", "wo_bin",
        "must lie in [0, " + std::to_string(g.bins() - 1) + "], got " + std::to_string(wo_bin));
  const auto d = g.cosine_weighted_areas();
  DirectionalAlbedo out{std::vector<double>(channels, 0.0), std::vector<double>(channels, 0.0)};
  for (int wi = 0; wi < g.bins(); ++wi) {
    auto& side = g.upper(wi) == g.upper(wo_bin) ? out.reflectance : out.transmittance;
    for (int c = 0; c < channels; ++c) side[c] += at(wi, wo_bin, c) * d[static_cast<size_t>(wi)];
  }
  return out;
}

std::vector<double> TabulatedBsdfTable::total_albedo() const {
  const DirectionGrid g = grid();
  const auto d = g.cosine_weighted_areas();
  std::vector<double> out(static_cast<size_t>(channels), 0.0);
  for (int wi = 0; wi < g.bins(); ++wi)
    for (int wo = 0; wo < g.bins(); ++wo)
      for (int c = 0; c < channels; ++c)
        out[static_cast<size_t>(c)] += at(wi, wo, c) * d[static_cast<size_t>(wi)] *
                                       d[static_cast<size_t>(wo)] / std::numbers::pi;
  return out;
}

}  // namespace weft
