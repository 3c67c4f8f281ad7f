#pragma once
// The fiber_table and fabric_table materials: a TabulatedBsdfTable reduced to RGB and prepared for
// sampling, shared immutable between every material that uses the same file.
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
// cos_avg is the mean |cos theta| over a cell. wi is uniform (in solid angle) within the chosen
// fine cell. pdf(wo, wi) = p_chart(wi | bin(wo)) / (4 pi), the fine cell taken within the table
// cell that DirectionGrid assigns wi, as sample does.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/distribution.h"
#include "weft/materials/bsdf.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct TabulatedBsdfData {
  DirectionGrid grid;
  std::string kind;                             // "fiber" | "fabric"
  std::map<std::string, std::string> metadata;  // from the table
  std::vector<float> rgb;                       // [wi_bin][wo_bin][3]
  std::vector<Distribution2D> sampling;         // one per wo bin, over fine wi cells
  int sampling_subdivision = 1;                 // fine cells per table cell, per side
  // Spectral tables: how many RGB components were negative (out of the sRGB gamut) after the
  // D65 band reduction and were set to 0. Always 0 for RGB tables.
  size_t clamped_components = 0;

  // Reduces a (validated) table to RGB and builds the per-wo-bin sampling distributions.
  static std::shared_ptr<const TabulatedBsdfData> prepare(const TabulatedBsdfTable& table);

  Rgb lookup(int wi_bin, int wo_bin) const {
    const size_t i = (static_cast<size_t>(wi_bin) * static_cast<size_t>(grid.bins()) +
                      static_cast<size_t>(wo_bin)) *
                     3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

struct TabulatedBsdf {
  std::shared_ptr<const TabulatedBsdfData> data;
  Rgb scale{1.0};  // tint * scale from the material parameters

  Rgb eval(const Vec3& wo, const Vec3& wi) const;
  std::optional<BsdfSample> sample(const Vec3& wo, Vec2 u, double u_lobe) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
};

}  // namespace weft
