#pragma once
// The measurement a verification compares against: a measured in-plane table (docs/verify.md).
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"

namespace weft {

// One incidence of a measured in-plane table; views in the paper's sign (> 0 on the mirror side).
struct MeasuredCurve {
  double theta_i_deg = 0;
  std::vector<double> view_deg;
  std::vector<Rgb> beta;
};

struct MeasuredInplane {
  std::string file;
  std::vector<MeasuredCurve> curves;  // by increasing theta_i
};

// Reads a table in the format of materials/data/measured/*/inplane.csv: optional comment lines
// starting with '#' or '"#', a header naming at least theta_i_deg, theta_o_deg, nbrdf_beta_R,
// nbrdf_beta_G, nbrdf_beta_B, and one row per (theta_i, theta_o) with theta_o < 0 on the mirror
// side (that table's convention; flipped here). weft::Error naming the file and the column (or
// line) on a missing file or column, a non-number, a negative or non-finite beta, an angle out of
// range, or a duplicate row.
MeasuredInplane read_measured_inplane(const std::filesystem::path& path);

// The bundled MERL red fabric (materials/data/measured/merl-red-fabric/inplane.csv), found in the
// source tree or the installed tree; weft::Error listing the places tried.
std::filesystem::path bundled_measured_inplane();

}  // namespace weft
