#pragma once
// The fiber_table and fabric_table materials: a TabulatedBsdfTable reduced to RGB (a spectral one
// also kept per band, for spectral renders) and prepared for sampling, shared immutable between
// every material that uses the same file.
//
// Evaluation: bilinear interpolation over the 4 nearest bin centres of the direction's own
// hemisphere in the DirectionGrid chart, separately for wo and for wi (16 table entries), clamped
// at the horizon. This makes f continuous within each hemisphere instead of faceted, and never
// blends reflection with transmission; the cell averages themselves are what the table stores.
//
// Sampling: for the bin b holding wo, a Distribution2D over a fine chart grid, each table cell c
// split into k x k fine cells s (k = sampling_subdivision: 32 fine cells per hemisphere side), a
// mixture of two parts:
//   shape (80%): g(b, s) = cos_avg(s) * mean over wo at the 2 x 2 quarter points of b of the
//     interpolated channel mean of f at the centre of s: follows f cos within a cell, where a
//     density flat over the cell against a peaked, interpolated f gives large weights;
//   coverage (20%): w(b, c) = cos_avg(c) * (m(b, c) + m3(b, c)) / 2, spread evenly over c's fine
//     cells, where m is the channel mean of the table and m3 its mean over the 3 x 3
//     neighbourhoods of b and of c within their hemispheres (what bilinear eval can reach): it
//     makes pdf > 0 wherever the interpolated f > 0, for any wo in b.
// cos_avg is the mean |cos theta| over a cell. A table read by cell (TableLookup::cell) is
// sampled by default with the shape taken from the cell pair's own value instead, cos_avg(s) *
// m(b, c(s)) (TabulatedBsdfData::cell_sampling): that is f cos itself up to cos within a fine
// cell, where the interpolated shape, peaked inside a cell whose read value is flat, gave the
// weights f cos / pdf of the cell's edges several times the albedo (fireflies in the fiber-level
// renders: docs/fabric-bsdf.md, "Noise of the fiber-level renders"). wi is uniform (in solid
// angle) within the chosen fine cell. pdf(wo, wi) = p_chart(wi | bin(wo)) / (4 pi), the fine cell
// taken within the table cell that DirectionGrid assigns wi, as sample does.
//
// Backing (fabric_table's backing_reflectance; docs/scenes.md): the cloth lies on an opaque
// Lambertian backing of albedo rho_b (upholstery foam). Light the cloth transmits downwards
// reaches the backing, bounces between it and the cloth's underside and leaves through the cloth
// (adding-doubling of a diffuse layer under a sheet):
//   f(wo, wi) = f_table(wo, wi) + rho_b / (1 - rho_b r_under) tau(wo) tau(wi) / pi
// for wo, wi above the cloth, 0 otherwise (a backed cloth is opaque, and black from below: the
// side below is the foam). tau(w) = int_lower f_table(w, w') |cos w'| dw' is the table's
// directional transmittance and r_under = (1/pi) int_lower int_lower f_table |cos| |cos| the
// underside's albedo under diffuse light. The backing re-emits diffusely whatever reaches it, so
// the cloth's underside is lit diffusely: the light returning from the backing is diffuse, which
// is what r_under and tau(wo) assume. The one approximation: tau(wi) stands for the fraction of
// light from wi that goes down, int_lower f_table(w', wi) |cos w'| dw', equal to it for a
// reciprocal table; one function for both keeps the backed BSDF reciprocal. (The paper's summed
// tables send nothing below the cloth, so that fraction would be 0: they are read here as the
// reciprocal sheet their transmission seen from above describes; their r_under is 0.) The
// backing is a plane in contact with the cloth (light leaves where it entered). tau and the
// albedos are the exact integrals of the interpolated table (hemisphere_weights), so a white
// furnace sees the closed form.
// Sampling with a backing: the table's reflection part (its sampling distribution restricted to
// wi above the cloth) or a cosine lobe for the backing term, chosen with probability in
// proportion to each part's albedo for this wo.
//
// Sheen (a fabric table's half-vector lobe, half_vector_lobe.h): eval reads the cells less the
// sheen's cell averages, interpolated, plus the sheen itself, so a mirror peak narrower than the
// bins stays sharp (read by cell, the rest's cell plus the sheen). The sampling
// distributions and the albedos above are the whole cells' (they cover the sheen's cells); without
// a backing, a share of the draws, half the sheen's share of the light arriving at wo's bin, takes
// the sheen's own: a window bin in proportion to the light the table booked there for wo's bin
// (the table taken as reciprocal), h uniform in it, wi = wo mirrored about h, density
// p(bin) / (its solid angle x 4 |wo . h|). With a backing only the cells' distribution samples.
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/distribution.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_modulation.h"

namespace weft {

struct TabulatedBsdfData {
  DirectionGrid grid;
  std::string kind;                             // "fiber" | "fabric"
  std::map<std::string, std::string> metadata;  // from the table
  std::string checksum;    // the table's values_fnv1a64 (TabulatedBsdfTable::checksum)
  std::vector<float> rgb;  // [wi_bin][wo_bin][3]
  // Spectral tables: the band values as stored, [wi_bin][wo_bin][kNumBands], which a spectral
  // render reads (TabulatedBsdf::eval_bands); empty for RGB tables. Sampling follows the RGB
  // mean either way (its coverage term keeps the density > 0 wherever any band is). Kept whether
  // or not a render is spectral: 11 times the RGB values' memory (R = 8: 2.2 MB, R = 12: 11 MB,
  // R = 32: 550 MB, the size of the file's own values).
  std::vector<float> bands;
  std::vector<Distribution2D> sampling;  // one per wo bin, over fine wi cells
  int sampling_subdivision = 1;          // fine cells per table cell, per side
  // Per wo bin o: the integral of the interpolated f(wo in o's centre footprint, wi) |cos wi|
  // over wi in o's own hemisphere (same_side: reflection, for the lower bins the underside's)
  // and in the other one (other_side: transmission): sum_i f[i][o] W_i (hemisphere_weights).
  // Interpolated over wo like f, they give the directional albedos of the interpolated table.
  std::vector<Rgb> same_side, other_side;
  // The underside's albedo under diffuse light from below, (1/pi) sum_{o lower} W_o same_side[o],
  // and the transmittance of diffuse light from above, (1/pi) sum_{o upper} W_o other_side[o].
  Rgb underside_diffuse_albedo, diffuse_transmittance;
  // Spectral tables: how many RGB components were negative (out of the sRGB gamut) after the
  // D65 band reduction and were set to 0. Always 0 for RGB tables.
  size_t clamped_components = 0;
  // The table's sheen (the top of this file), its light out of rgb and bands: sheen_rgb in RGB,
  // sheen_bands a spectral table's as stored; per wo bin of the sheen's light grid the draw of its
  // window bins, and per table bin the share of the draws it takes. Empty when the table has none.
  std::optional<HalfVectorLobe> sheen_rgb, sheen_bands;
  std::vector<Distribution1D> sheen_sampling;
  std::vector<double> sheen_share;

  // Reduces a (validated) table to RGB and builds the per-wo-bin sampling distributions.
  static std::shared_ptr<const TabulatedBsdfData> prepare(const TabulatedBsdfTable& table);

  // The per-wo-bin distributions whose shape follows the cell pairs' own values (for tables read
  // by cell; the top of this file), same fine cells and coverage as 'sampling'. Built on first
  // use, once, whichever thread asks (the same values either way): most tables are never read
  // by cell, and the distributions take as much memory as 'sampling'.
  const std::vector<Distribution2D>& cell_sampling() const;
  mutable std::once_flag cell_sampling_once;
  mutable std::vector<Distribution2D> cell_sampling_built;

  // A per-bin quantity interpolated at direction w like eval interpolates f over wo.
  Rgb interpolate(const std::vector<Rgb>& per_bin, const Vec3& w) const;

  Rgb lookup(int wi_bin, int wo_bin) const {
    const size_t i = (static_cast<size_t>(wi_bin) * static_cast<size_t>(grid.bins()) +
                      static_cast<size_t>(wo_bin)) *
                     3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
  // The band values of a spectral table's cell pair.
  const float* lookup_bands(int wi_bin, int wo_bin) const {
    return &bands[(static_cast<size_t>(wi_bin) * static_cast<size_t>(grid.bins()) +
                   static_cast<size_t>(wo_bin)) *
                  kNumBands];
  }
};

// W_k = the integral of bin k's interpolation weight (DirectionGrid::bilinear) times |cos theta|
// over its hemisphere: the integral of the interpolated f over wi is sum_k f[k][o] W_k. Per table
// cell by midpoint quadrature on 8 x 8 equal-area points, scaled so that the cell's total is
// its exact D_k; so sum_k W_k = pi per hemisphere exactly (the weights sum to 1 everywhere).
std::vector<double> hemisphere_weights(const DirectionGrid& grid);

// An opaque Lambertian backing under a table (fabric_table's backing_reflectance): what
// TabulatedBsdf needs, from the table's data, its scale and rho_b (see the top of this file).
struct TableBacking {
  Rgb reflectance;            // rho_b, each component in [0, 1)
  Rgb gain;                   // rho_b / (1 - rho_b r_under) / pi, with r_under of the scaled table
  Rgb diffuse_transmittance;  // of the scaled table, for diffuse light from above
  // Throws weft::Error (field "") when rho_b r_under >= 1 (a scale > 1 can make the underside
  // reflect more than it receives).
  static TableBacking make(const TabulatedBsdfData& data, const Rgb& scale, const Rgb& rho_b);
};

// How eval reads the table between cell centres (fiber_table's "interpolation"). bilinear: the
// default above, smooth within each hemisphere. cell: the cell's own average, constant over the
// cell pair that holds (wi, wo): what the fabric ray trace draws from (fabric_raytrace.h), so a
// fiber-level render and the ray-traced fabric table of the same sample are one transport, and
// every cell pair carries exactly its stored energy. Bilinear interpolation does not keep a
// peaked table's cell integrals: on the bundled poplin with red cotton at R = 8 the fiber-level
// render's red fell 1.6 % below the ray trace with bilinear, within noise with cell
// (docs/fabric-bsdf.md, "One transport, two estimators").
enum class TableLookup { bilinear, cell };

struct TabulatedBsdf {
  std::shared_ptr<const TabulatedBsdfData> data;
  Rgb scale{1.0};  // tint * scale from the material parameters
  TableLookup lookup = TableLookup::bilinear;
  std::optional<TableBacking> backing =
      std::nullopt;  // none: the bare table (transmission included)
  // fabric_table's weave (weave_modulation.h); null for every other table. This BSDF is the
  // table level; the renderer binds the weave level to a hit (bound_bsdf.h).
  std::shared_ptr<const TableWeave> weave = nullptr;
  // What the sampling density follows within a table cell: the interpolated f (bilinear) or the
  // cell pair's own value (cell). fiber_table's "sampling", by default its "interpolation".
  TableLookup sampling = TableLookup::bilinear;

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
  // A spectral render's f per band (bsdfs.h eval_bands), read like eval reads the RGB values: for
  // a spectral table without a backing; its scale is then grey (scale.r is used).
  void eval_bands(const Vec3& wo, const Vec3& wi, Spectrum& out) const;

  // The backing term alone (0 without a backing), for the tests.
  Rgb eval_backing(const Vec3& wo, const Vec3& wi) const;

 private:
  Rgb eval_table(const Vec3& wo, const Vec3& wi) const;
  double pdf_table(const Vec3& wo, const Vec3& wi) const;
  double pdf_sheen(const Vec3& wo, const Vec3& wi) const;
  std::optional<Vec3> sample_sheen(const Vec3& wo, Vec2 u, double u_bin) const;
  // The sheen's share of the draws for wo: 0 without a sheen, with a backing or read by cell.
  double sheen_share(const Vec3& wo) const;
  const Distribution2D& distribution(const Vec3& wo) const;
  // With a backing: the probability of sampling the table's reflection part for wo, and that
  // part's share of the table's sampling distribution (wi above the cloth).
  struct BackedLobes {
    double p_table = 0, upper_mass = 0;
  };
  BackedLobes backed_lobes(const Vec3& wo) const;
  double pdf_backed(const BackedLobes& lobes, const Vec3& wo, const Vec3& wi) const;
};

}  // namespace weft
