#pragma once
// A table read as a reader that knows its sheen reads it: f(wo, wi) = the cells less the sheen's
// cell averages (TabulatedBsdfTable::without_sheen), interpolated, plus the sheen itself
// (HalfVectorLobe::eval), so that a mirror peak narrower than the bins stays sharp; a table
// without a sheen is interpolated as it is (TabulatedBsdfTable::interpolate, the same bits).
// This is what the renderer's TabulatedBsdf evaluates; the figures and exports read tables
// through it so that they show what the renderer shows.
//
// The rest (a quadrature of the sheen's cell averages, half_vector_lobe.h) is made once, when the
// reader is made; copies share it. A reader of a table without a sheen does not copy the table:
// that table must outlive the reader and its copies.
#include <memory>
#include <optional>
#include <span>

#include "weft/core/vec.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

class TableReader {
 public:
  // Reads 'table' (the sheen's quadrature on 'threads' threads, the same bits at any count).
  explicit TableReader(const TabulatedBsdfTable& table, int threads = 0);
  // A reader of parts already made: 'cells' interpolated (holding no sheen) plus 'sheen'
  // (table_to_rgb's reduction of a reader). Both are kept.
  TableReader(TabulatedBsdfTable cells, std::optional<HalfVectorLobe> sheen);

  int channels() const { return cells_->channels; }
  int resolution() const { return cells_->resolution; }
  // What is interpolated: the whole table without a sheen, the rest with one.
  const TabulatedBsdfTable& cells() const { return *cells_; }
  const HalfVectorLobe* sheen() const { return sheen_.get(); }

  // f(wo, wi) per channel into 'out' (channels() values, 1/sr); thread-safe.
  void eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const;

 private:
  std::shared_ptr<const TabulatedBsdfTable> cells_;
  std::shared_ptr<const HalfVectorLobe> sheen_;
};

}  // namespace weft
