#include "weft/materials/tabulated_bsdf.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/core/spectrum.h"

namespace weft {
namespace {

// The 3 x 3 block of bins around 'bin' within its hemisphere (clamped at the horizon, like the
// bilinear footprint, which never reaches across it).
std::array<int, 9> neighbourhood(const DirectionGrid& grid, int bin) {
  const int r = grid.resolution, hemi = grid.upper(bin) ? 0 : 1;
  const int x = bin % r, y = (bin / r) % r;
  std::array<int, 9> out{};
  int k = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      out[k++] = (hemi * r + std::clamp(y + dy, 0, r - 1)) * r + std::clamp(x + dx, 0, r - 1);
  return out;
}

// How many fine sampling cells each table cell is split into per side: enough that the fine grid
// has 32 cells per hemisphere side (a 2048-cell distribution per wo bin), at least 1.
int subdivision_for(int resolution) {
  return std::max(1, 32 / resolution);
}

// The share of the sampling density that is flat over each table cell (the coverage term).
constexpr double kSamplingCoverage = 0.2;

}  // namespace

std::vector<double> hemisphere_weights(const DirectionGrid& grid) {
  constexpr int kPoints = 8;  // per side of each table cell
  const int n = grid.bins();
  const std::vector<double> d = grid.cosine_weighted_areas();
  std::vector<double> w(static_cast<size_t>(n), 0.0);
  for (int k = 0; k < n; ++k) {
    // Equal-area points: each stands for the same solid angle, so |cos| weights them.
    std::array<double, 16> hat{};  // per footprint bin of the cell's points (at most 9 bins)
    std::array<int, 16> bin{};
    int used = 0;
    double cos_sum = 0;
    for (int py = 0; py < kPoints; ++py)
      for (int px = 0; px < kPoints; ++px) {
        const Vec2 c = grid.chart_point(k, (px + 0.5) / kPoints, (py + 0.5) / kPoints);
        const double cz = std::abs(DirectionGrid::to_direction(c).z);
        cos_sum += cz;
        const auto fp = grid.bilinear(c);
        for (int a = 0; a < 4; ++a) {
          int j = 0;
          while (j < used && bin[j] != fp.bin[a]) ++j;
          if (j == used) bin[used++] = fp.bin[a];
          hat[j] += fp.weight[a] * cz;
        }
      }
    if (cos_sum > 0)
      for (int j = 0; j < used; ++j) w[bin[j]] += d[k] * hat[j] / cos_sum;
  }
  return w;
}

Rgb TabulatedBsdfData::interpolate(const std::vector<Rgb>& per_bin, const Vec3& w) const {
  const auto fp = grid.bilinear(DirectionGrid::to_chart(w));
  Rgb sum;
  for (int a = 0; a < 4; ++a) sum += per_bin[fp.bin[a]] * fp.weight[a];
  return sum;
}

TableBacking TableBacking::make(const TabulatedBsdfData& data, const Rgb& scale, const Rgb& rho_b) {
  const Rgb r_under = data.underside_diffuse_albedo * scale;
  // 1 - rho_b r_under per channel: the series of bounces between backing and cloth converges.
  auto one_minus = [](double x) { return 1 - x; };
  const Rgb rr = rho_b * r_under;
  const Rgb denominator{one_minus(rr.r), one_minus(rr.g), one_minus(rr.b)};
  if (!(denominator.r > 0 && denominator.g > 0 && denominator.b > 0))
    throw Error("the backing (reflectance " + ParamReader::fmt(rho_b.max_component()) +
                ") and the cloth's underside (diffuse albedo " +
                ParamReader::fmt(r_under.max_component()) +
                " with this tint and scale) would reflect all the light between them");
  TableBacking b;
  b.reflectance = rho_b;
  b.gain = Rgb(rho_b.r / denominator.r, rho_b.g / denominator.g, rho_b.b / denominator.b) * kInvPi;
  b.diffuse_transmittance = data.diffuse_transmittance * scale;
  return b;
}

namespace {

// Index of the cell pair (wi, wo) in an n x n table.
size_t cell_at(int n, int wi, int wo) {
  return static_cast<size_t>(wi) * n + static_cast<size_t>(wo);
}

// The table's RGB into data.rgb (spectral tables reduced and gamut-clipped, their bands kept);
// returns the channel mean m per cell, which drives sampling.
std::vector<float> reduce_to_rgb(const TabulatedBsdfTable& table, TabulatedBsdfData& data) {
  const size_t cells = data.rgb.size() / 3;
  std::vector<float> mean(cells);
  GamutClip gamut;
  for (size_t cell = 0; cell < cells; ++cell) {
    Rgb c;
    if (table.channels == 3) {
      c = {table.values[cell * 3], table.values[cell * 3 + 1], table.values[cell * 3 + 2]};
    } else {
      const float* v = &table.values[cell * table.channels];
      c = bands_to_linear_srgb([v](int b) { return v[b]; });
      gamut.clip(c);
    }
    data.rgb[cell * 3] = static_cast<float>(c.r);
    data.rgb[cell * 3 + 1] = static_cast<float>(c.g);
    data.rgb[cell * 3 + 2] = static_cast<float>(c.b);
    mean[cell] = static_cast<float>(c.average());
  }
  data.clamped_components = gamut.components;
  if (table.channels == kNumBands) data.bands = table.values;
  return mean;
}

// m3: the mean of m over the 3 x 3 neighbourhoods of the wi bin and of the wo bin (separably).
std::vector<float> neighbourhood_means(const DirectionGrid& grid, const std::vector<float>& mean) {
  const int n = grid.bins();
  std::vector<std::array<int, 9>> nbr(n);
  for (int b = 0; b < n; ++b) nbr[b] = neighbourhood(grid, b);
  std::vector<float> tmp(mean.size()), blur(mean.size());
  for (int wi = 0; wi < n; ++wi)
    for (int wo = 0; wo < n; ++wo) {
      double s = 0;
      for (int k : nbr[wi]) s += mean[cell_at(n, k, wo)];
      tmp[cell_at(n, wi, wo)] = static_cast<float>(s / 9);
    }
  for (int wi = 0; wi < n; ++wi)
    for (int wo = 0; wo < n; ++wo) {
      double s = 0;
      for (int k : nbr[wo]) s += tmp[cell_at(n, wi, k)];
      blur[cell_at(n, wi, wo)] = static_cast<float>(s / 9);
    }
  return blur;
}

// The fine grid: each table cell split k x k, so the density follows the interpolated f cos
// within a cell instead of being flat over it (a flat cell density against a peaked, bilinearly
// interpolated f gave a few samples large weights: speckle on indirect light).
struct FineGrid {
  int k = 1, fr = 0, fn = 0;   // cells per table cell side; resolution; bins
  std::vector<double> cos;     // mean |cos theta| over each fine cell
  std::vector<Vec3> dir;       // each fine cell's centre
  std::vector<int> coarse_of;  // the table cell each fine cell lies in
};
FineGrid fine_grid(int r) {
  FineGrid f;
  f.k = subdivision_for(r);
  f.fr = f.k * r;
  const DirectionGrid fine{f.fr};
  f.fn = fine.bins();
  f.cos = fine.cosine_weighted_areas();
  for (double& c : f.cos) c /= fine.bin_solid_angle();
  f.dir.resize(f.fn);
  f.coarse_of.resize(f.fn);
  for (int s = 0; s < f.fn; ++s) {
    f.dir[s] = fine.bin_center(s);
    const int x = s % f.fr, row = s / f.fr;
    f.coarse_of[s] = (row / f.k) * r + x / f.k;
  }
  return f;
}

// The directional albedos of the interpolated table per wo bin, and its diffuse ones.
void add_albedos(TabulatedBsdfData& data) {
  const DirectionGrid& grid = data.grid;
  const int n = grid.bins();
  const std::vector<double> hw = hemisphere_weights(grid);
  data.same_side.assign(n, Rgb(0.0));
  data.other_side.assign(n, Rgb(0.0));
  for (int wo = 0; wo < n; ++wo)
    for (int wi = 0; wi < n; ++wi) {
      const Rgb f = data.lookup(wi, wo) * hw[wi];
      (grid.upper(wi) == grid.upper(wo) ? data.same_side : data.other_side)[wo] += f;
    }
  for (int wo = 0; wo < n; ++wo) {
    if (grid.upper(wo))
      data.diffuse_transmittance += data.other_side[wo] * (hw[wo] * kInvPi);
    else
      data.underside_diffuse_albedo += data.same_side[wo] * (hw[wo] * kInvPi);
  }
}

// The shape of the sampling density for wo bin 'wo' read by cell: the cell pair's channel mean
// times |cos| of each fine cell, f cos itself where f is the cell's value.
std::vector<double> cell_shape(int n, int wo, const std::vector<float>& mean,
                               const FineGrid& fine) {
  std::vector<double> shape(fine.fn);
  for (int s = 0; s < fine.fn; ++s)
    shape[s] =
        std::max(0.0, static_cast<double>(mean[cell_at(n, fine.coarse_of[s], wo)])) * fine.cos[s];
  return shape;
}

// The sampling density over fine wi cells for wo bin 'wo': a share kSamplingCoverage flat over
// each table cell, the rest following f cos, interpolated (follow bilinear) or the cell's own
// value (follow cell).
Distribution2D wi_sampling(const DirectionGrid& grid, int wo, const std::vector<float>& mean,
                           const std::vector<float>& blur, const std::vector<double>& cos_avg,
                           const FineGrid& fine, TableLookup follow) {
  const int n = grid.bins(), fn = fine.fn, k = fine.k;
  // Coverage: per table cell, cos_avg * (m + m3) / 2, which is > 0 wherever the interpolated f
  // can be for any wo in this bin.
  std::vector<double> cell(n);
  double cell_sum = 0;
  for (int wi = 0; wi < n; ++wi) {
    cell[wi] = cos_avg[wi] * 0.5 *
               (static_cast<double>(mean[cell_at(n, wi, wo)]) + blur[cell_at(n, wi, wo)]);
    cell_sum += cell[wi];
  }
  // Shape: the interpolated channel mean times |cos| at the centre of each fine cell, averaged
  // over wo at the 2 x 2 quarter points of its bin (eval interpolates over wo too).
  std::array<Vec3, 4> wo_at;
  for (int q = 0; q < 4; ++q)
    wo_at[q] = DirectionGrid::to_direction(
        grid.chart_point(wo, 0.25 + 0.5 * (q % 2), 0.25 + 0.5 * (q / 2)));
  std::vector<double> shape(fn);
  double shape_sum = 0;
  if (follow == TableLookup::cell) {
    shape = cell_shape(n, wo, mean, fine);
    for (double v : shape) shape_sum += v;
  } else {
    for (int s = 0; s < fn; ++s) {
      double v = 0;
      for (const Vec3& o_dir : wo_at)
        for_each_interpolated_cell(grid, o_dir, fine.dir[s], [&](int i, int o, double w) {
          v += mean[cell_at(n, i, o)] * w;
        });
      shape[s] = std::max(0.0, v) * fine.cos[s];
      shape_sum += shape[s];
    }
  }
  std::vector<double> w(fn, 0.0);
  if (cell_sum > 0) {
    const double a = shape_sum > 0 ? kSamplingCoverage : 1.0;
    for (int s = 0; s < fn; ++s) {
      w[s] = a * cell[fine.coarse_of[s]] / (cell_sum * k * k);
      if (shape_sum > 0) w[s] += (1 - a) * shape[s] / shape_sum;
    }
  }
  return Distribution2D(w, static_cast<size_t>(fine.fr), static_cast<size_t>(2 * fine.fr));
}

// The sheen's RGB (a spectral one reduced like the cells) into data, the rest's values into rgb and
// bands, and the sheen's draws: per wo bin b of the sheen's light grid its window bins in
// proportion to the light booked there for light from b (the table taken as reciprocal), and per
// table bin its share of the draws, half the sheen's share of the light arriving there
// (sheen_cells: its cell averages).
void prepare_sheen(const TabulatedBsdfTable& table, const TabulatedBsdfTable& rest,
                   const std::vector<double>& sheen_cells, TabulatedBsdfData& data) {
  reduce_to_rgb(rest, data);
  const HalfVectorLobe& s = *table.sheen;
  const size_t nc = static_cast<size_t>(table.channels), pairs = s.values.size() / nc;
  HalfVectorLobe rgb = s;
  rgb.channels = 3;
  rgb.values.resize(pairs * 3);
  GamutClip gamut;
  for (size_t p = 0; p < pairs; ++p) {
    const float* v = &s.values[p * nc];
    Rgb c = nc == 3 ? Rgb{v[0], v[1], v[2]} : bands_to_linear_srgb([v](int b) { return v[b]; });
    if (nc != 3) gamut.clip(c);
    rgb.values[p * 3] = static_cast<float>(c.r);
    rgb.values[p * 3 + 1] = static_cast<float>(c.g);
    rgb.values[p * 3 + 2] = static_cast<float>(c.b);
  }
  data.clamped_components += gamut.components;
  if (nc == kNumBands) data.sheen_bands = s;
  const std::vector<double> m = s.mean_projections();
  const int n = data.grid.bins(), n_light = s.light_grid().bins();
  const size_t nk = static_cast<size_t>(s.window_bins());
  const std::vector<double> d = data.grid.cosine_weighted_areas();
  data.sheen_sampling.resize(static_cast<size_t>(n_light));
  for (int b = 0; b < n_light; ++b) {
    std::vector<double> w(nk);
    for (size_t k = 0; k < nk; ++k) {
      const size_t at = (s.slot(b) * nk + k) * 3;
      w[k] = (rgb.values[at] + rgb.values[at + 1] + rgb.values[at + 2]) * m[at / 3];
    }
    data.sheen_sampling[static_cast<size_t>(b)] = Distribution1D(w);
  }
  data.sheen_share.assign(static_cast<size_t>(n), 0.0);
  for (int b = 0; b < n; ++b) {
    double part = 0, whole = 0;
    for (int i = 0; i < n; ++i)
      for (size_t c = 0; c < nc; ++c) {
        const size_t v = (static_cast<size_t>(i) * n + static_cast<size_t>(b)) * nc + c;
        part += sheen_cells[v] * d[i];
        whole += table.values[v] * d[i];
      }
    if (part > 0 && whole > 0) data.sheen_share[b] = 0.5 * std::min(1.0, part / whole);
  }
  data.sheen_rgb = std::move(rgb);
}

}  // namespace

std::shared_ptr<const TabulatedBsdfData> TabulatedBsdfData::prepare(
    const TabulatedBsdfTable& table) {
  table.validate("");
  auto data = std::make_shared<TabulatedBsdfData>();
  const DirectionGrid grid = table.grid();
  const int n = grid.bins();
  const size_t cells = static_cast<size_t>(n) * static_cast<size_t>(n);
  data->grid = grid;
  data->kind = table.kind;
  data->metadata = table.metadata;
  data->checksum = table.checksum();
  data->rgb.resize(cells * 3);
  const std::vector<float> mean = reduce_to_rgb(table, *data);
  const std::vector<float> blur = neighbourhood_means(grid, mean);

  // Mean |cos theta| over each cell.
  std::vector<double> cos_avg = grid.cosine_weighted_areas();
  for (double& c : cos_avg) c /= grid.bin_solid_angle();
  const FineGrid fine = fine_grid(grid.resolution);
  data->sampling_subdivision = fine.k;
  add_albedos(*data);

  data->sampling.resize(n);
  parallel_for(static_cast<uint64_t>(n), 0, [&](uint64_t task) {
    const int wo = static_cast<int>(task);
    data->sampling[wo] = wi_sampling(grid, wo, mean, blur, cos_avg, fine, TableLookup::bilinear);
  });
  if (table.sheen) {
    std::vector<double> sheen_cells;
    const TabulatedBsdfTable rest = table.without_sheen("", 0, &sheen_cells);
    prepare_sheen(table, rest, sheen_cells, *data);
  }
  return data;
}

const std::vector<Distribution2D>& TabulatedBsdfData::cell_sampling() const {
  std::call_once(cell_sampling_once, [this] {
    // The channel means again, from the stored RGB (prepare's own are not kept).
    const int n = grid.bins();
    std::vector<float> mean(rgb.size() / 3);
    for (size_t c = 0; c < mean.size(); ++c)
      mean[c] = static_cast<float>((double(rgb[3 * c]) + rgb[3 * c + 1] + rgb[3 * c + 2]) / 3);
    const std::vector<float> blur = neighbourhood_means(grid, mean);
    std::vector<double> cos_avg = grid.cosine_weighted_areas();
    for (double& c : cos_avg) c /= grid.bin_solid_angle();
    const FineGrid fine = fine_grid(grid.resolution);
    // One thread: this may run inside a render's worker (one pass over wo bin x fine cell).
    cell_sampling_built.resize(n);
    for (int wo = 0; wo < n; ++wo)
      cell_sampling_built[wo] = wi_sampling(grid, wo, mean, blur, cos_avg, fine, TableLookup::cell);
  });
  return cell_sampling_built;
}

Rgb TabulatedBsdf::eval_table(const Vec3& wo, const Vec3& wi) const {
  Rgb sum;
  if (data->sheen_rgb) {
    std::array<double, 3> s{};
    data->sheen_rgb->eval(wo, wi, s);
    sum = {s[0], s[1], s[2]};
  }
  if (lookup == TableLookup::cell)
    return (sum + data->lookup(data->grid.bin_of(wi), data->grid.bin_of(wo))) * scale;
  for_each_interpolated_cell(data->grid, wo, wi,
                             [&](int i, int o, double w) { sum += data->lookup(i, o) * w; });
  return sum * scale;
}

void TabulatedBsdf::eval_bands(const Vec3& wo, const Vec3& wi, Spectrum& out) const {
  out.fill(0.0);
  if (!data || data->bands.empty()) return;
  auto add = [&](int i, int o, double w) {
    const float* v = data->lookup_bands(i, o);
    for (int b = 0; b < kNumBands; ++b) out[b] += w * v[b];
  };
  if (lookup == TableLookup::cell)
    add(data->grid.bin_of(wi), data->grid.bin_of(wo), scale.r);
  else
    for_each_interpolated_cell(data->grid, wo, wi,
                               [&](int i, int o, double w) { add(i, o, w * scale.r); });
  if (data->sheen_bands) {
    Spectrum s;
    data->sheen_bands->eval(wo, wi, s);
    for (int b = 0; b < kNumBands; ++b) out[b] += scale.r * s[b];
  }
}

Rgb TabulatedBsdf::eval_backing(const Vec3& wo, const Vec3& wi) const {
  if (!data || !backing || !(wo.z > 0) || !(wi.z > 0)) return Rgb(0.0);
  return backing->gain * scale * scale * data->interpolate(data->other_side, wo) *
         data->interpolate(data->other_side, wi);
}

Rgb TabulatedBsdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!data) return Rgb(0.0);  // a default-constructed value is black, never a crash
  if (!backing) return eval_table(wo, wi);
  // Backed: opaque, and black from below (the side below is the foam).
  if (!(wo.z > 0) || !(wi.z > 0)) return Rgb(0.0);
  return eval_table(wo, wi) + eval_backing(wo, wi);
}

const Distribution2D& TabulatedBsdf::distribution(const Vec3& wo) const {
  const int bin = data->grid.bin_of(wo);
  return sampling == TableLookup::cell ? data->cell_sampling()[bin] : data->sampling[bin];
}

double TabulatedBsdf::pdf_table(const Vec3& wo, const Vec3& wi) const {
  const DirectionGrid& grid = data->grid;
  const Distribution2D& dist = distribution(wo);
  if (dist.integral() == 0) return 0;
  // The density is constant over each fine cell: evaluate it at the centre of the fine cell that
  // holds wi, taken within the table cell the grid assigns, so the table cell is decided by
  // DirectionGrid alone.
  const int bin = grid.bin_of(wi), r = grid.resolution, k = data->sampling_subdivision;
  const Vec2 p = DirectionGrid::to_chart(wi);
  const int cx = bin % r, crow = bin / r;
  const int fx = std::clamp(static_cast<int>(std::floor(p.x * k * r)), cx * k, cx * k + k - 1);
  const int frow =
      std::clamp(static_cast<int>(std::floor(p.y * 2 * k * r)), crow * k, crow * k + k - 1);
  const Vec2 centre{(fx + 0.5) / (k * r), (frow + 0.5) / (2.0 * k * r)};
  return dist.pdf(centre) * kInv4Pi;  // area on the chart = solid angle / (4 pi)
}

TabulatedBsdf::BackedLobes TabulatedBsdf::backed_lobes(const Vec3& wo) const {
  BackedLobes l;
  const Distribution2D& dist = distribution(wo);
  // The upper hemisphere is the first half of the chart's rows.
  if (dist.integral() > 0) l.upper_mass = dist.marginal().cdf(dist.nv() / 2);
  const double table =
      l.upper_mass > 0 ? (data->interpolate(data->same_side, wo) * scale).average() : 0.0;
  const double back = (backing->gain * scale * data->interpolate(data->other_side, wo) * kPi *
                       backing->diffuse_transmittance)
                          .average();
  l.p_table = table + back > 0 ? table / (table + back) : -1;  // -1: nothing to sample
  return l;
}

double TabulatedBsdf::pdf_backed(const BackedLobes& l, const Vec3& wo, const Vec3& wi) const {
  if (l.p_table < 0 || !(wi.z > 0)) return 0;
  double p = (1 - l.p_table) * wi.z * kInvPi;
  if (l.p_table > 0) p += l.p_table * pdf_table(wo, wi) / l.upper_mass;
  return p;
}

double TabulatedBsdf::sheen_share(const Vec3& wo) const {
  if (backing || data->sheen_share.empty()) return 0;
  // Nothing to draw where wo's light bin (of the sheen's own grid) booked no sheen.
  const size_t light_bin = static_cast<size_t>(data->sheen_rgb->light_grid().bin_of(wo));
  if (!(data->sheen_sampling[light_bin].integral() > 0)) return 0;
  return data->sheen_share[static_cast<size_t>(data->grid.bin_of(wo))];
}

double TabulatedBsdf::pdf_sheen(const Vec3& wo, const Vec3& wi) const {
  const HalfVectorLobe& s = *data->sheen_rgb;
  const Vec3 sum = wo + wi;
  if (!(wo.z * wi.z > 0) || !(length(sum) > 0)) return 0;
  const Vec3 h = sum / length(sum);
  const int k = s.window_bin_of(h);
  if (k < 0) return 0;
  const Distribution1D& d = data->sheen_sampling[static_cast<size_t>(s.light_grid().bin_of(wo))];
  return d.pmf(static_cast<size_t>(k)) / (s.window_bin_solid_angle() * 4 * std::abs(dot(wo, h)));
}

std::optional<Vec3> TabulatedBsdf::sample_sheen(const Vec3& wo, Vec2 u, double u_bin) const {
  const HalfVectorLobe& s = *data->sheen_rgb;
  const Distribution1D& d = data->sheen_sampling[static_cast<size_t>(s.light_grid().bin_of(wo))];
  Vec3 h = s.window_point(static_cast<int>(d.sample_discrete(u_bin)), u.x, u.y);
  if (wo.z < 0) h.z = -h.z;
  const double wo_h = dot(wo, h);
  const Vec3 wi = 2 * wo_h * h - wo;
  if (!(wo_h > 0) || !(wi.z * wo.z > 0)) return std::nullopt;
  return normalize(wi);
}

double TabulatedBsdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!data) return 0;
  if (!backing) {
    const double s = sheen_share(wo);
    return s > 0 ? (1 - s) * pdf_table(wo, wi) + s * pdf_sheen(wo, wi) : pdf_table(wo, wi);
  }
  if (!(wo.z > 0) || !(wi.z > 0)) return 0;
  return pdf_backed(backed_lobes(wo), wo, wi);
}

std::optional<BsdfSample> TabulatedBsdf::sample(const Vec3& wo, Vec2 u, double u_lobe) const {
  if (!data) return std::nullopt;
  const Distribution2D& dist = distribution(wo);
  Vec3 wi;
  double p = 0;
  if (!backing) {
    const double s = sheen_share(wo);
    if (u_lobe < s) {
      const std::optional<Vec3> drawn = sample_sheen(wo, u, u_lobe / s);
      if (!drawn) return std::nullopt;
      wi = *drawn;
    } else {
      if (dist.integral() == 0) return std::nullopt;
      wi = DirectionGrid::to_direction(dist.sample(u).p);
    }
    p = pdf(wo, wi);
  } else {
    if (!(wo.z > 0)) return std::nullopt;
    const BackedLobes l = backed_lobes(wo);
    if (l.p_table < 0) return std::nullopt;
    if (u_lobe < l.p_table) {
      // The reflection part: the table's distribution restricted to its upper rows.
      wi = DirectionGrid::to_direction(dist.sample({u.x, u.y * l.upper_mass}).p);
    } else {
      wi = sample_cosine_hemisphere(u);
    }
    p = pdf_backed(l, wo, wi);  // 0 below the cloth
  }
  if (!(p > 0)) return std::nullopt;
  return BsdfSample{wi, eval(wo, wi) * (std::abs(wi.z) / p), p, false};
}

}  // namespace weft
