#pragma once
// A Weft table as the exchange formats see it. Every format here is isotropic or written
// isotropic: f(wo, wi) is averaged over rotations of both directions about the normal (the
// table's anisotropy, the fiber / warp axis along x, is dropped). wo is the direction towards the
// viewer and wi towards the light (bsdf_table.h: values[wi_bin][wo_bin], f in 1/sr). The table
// is read with its sheen, as the renderer reads it (materials/table_reader.h).
#include <span>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/table_reader.h"

namespace weft {

class TableView {
 public:
  // 'azimuths' rotations 2 pi k / azimuths, k = 0 .. azimuths - 1.
  explicit TableView(const TabulatedBsdfTable& table, int azimuths = 16);

  const TabulatedBsdfTable& table() const { return table_; }
  // f(wo, wi) of the table itself, at one rotation (TableReader::eval).
  const TableReader& reader() const { return reader_; }
  int channels() const { return table_.channels; }
  bool spectral() const { return table_.channels == kNumBands; }
  // The mean over the rotations of the table's f(wo, wi) (TableReader::eval: the cells
  // interpolated, with the sheen when the table holds one), one value per channel.
  void isotropic(const Vec3& wo, const Vec3& wi, std::span<double> out) const;
  // Y of one value per channel: the Y row of the sRGB (IEC 61966-2-1) matrix for an RGB table,
  // CIE 1931 y-bar under D65 (normalized so that a white reflector has Y = 1) for a spectral one.
  double luminance(std::span<const double> values) const;
  // Linear sRGB of one value per channel (spectral tables: bands_to_linear_srgb, negative
  // components, outside the gamut, set to 0 and counted in 'clip').
  Rgb rgb(std::span<const double> values, GamutClip* clip = nullptr) const;

 private:
  const TabulatedBsdfTable& table_;
  TableReader reader_;
  std::vector<double> cos_, sin_;
  std::vector<double> y_weights_;
};

}  // namespace weft
