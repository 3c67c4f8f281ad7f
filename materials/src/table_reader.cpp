#include "weft/materials/table_reader.h"

#include <vector>

#include "weft/core/error.h"

namespace weft {

TableReader::TableReader(const TabulatedBsdfTable& table, int threads) {
  if (!table.sheen) {
    // Not owned: an aliasing pointer with no control block (the header's lifetime rule).
    cells_ = std::shared_ptr<const TabulatedBsdfTable>(std::shared_ptr<void>(), &table);
    return;
  }
  cells_ = std::make_shared<const TabulatedBsdfTable>(table.without_sheen("", threads));
  sheen_ = std::make_shared<const HalfVectorLobe>(*table.sheen);
}

TableReader::TableReader(TabulatedBsdfTable cells, std::optional<HalfVectorLobe> sheen) {
  if (cells.sheen) throw Error("", "sheen", "a reader's cells hold no sheen; pass it apart");
  if (sheen && (sheen->channels != cells.channels || sheen->resolution != cells.resolution))
    throw Error("", "sheen", "the sheen's shape does not fit the cells");
  cells_ = std::make_shared<const TabulatedBsdfTable>(std::move(cells));
  if (sheen) sheen_ = std::make_shared<const HalfVectorLobe>(std::move(*sheen));
}

void TableReader::eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const {
  cells_->interpolate(wo, wi, out);
  if (!sheen_) return;
  // The lobe's values for one direction pair: on the stack for an RGB table, else a small vector.
  double rgb[3];
  std::vector<double> bands;
  std::span<double> s(rgb, 3);
  if (out.size() != 3) {
    bands.resize(out.size());
    s = bands;
  }
  sheen_->eval(wo, wi, s);
  for (size_t c = 0; c < out.size(); ++c) out[c] += s[c];
}

}  // namespace weft
