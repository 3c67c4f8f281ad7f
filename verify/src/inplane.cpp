#include "weft/verify/inplane.h"

namespace weft {

std::vector<std::vector<Rgb>> table_curves(const TabulatedBsdfTable& table,
                                           const MeasuredInplane& measured, int azimuths) {
  const TableReader rgb = table_to_rgb(TableReader(table));
  std::vector<std::vector<Rgb>> out;
  for (const auto& c : measured.curves)
    out.push_back(inplane_beta(rgb, c.theta_i_deg, c.view_deg, azimuths));
  return out;
}

}  // namespace weft
