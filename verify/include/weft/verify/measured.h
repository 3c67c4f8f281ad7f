#pragma once
// The measurement a verification compares against: a measured in-plane table (docs/verify.md).
#include <cstdint>
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

// In-plane curves, per incidence, at every view of the measured table: [incidence][view].
using InplaneCurves = std::vector<std::vector<Rgb>>;

// One fit of the measurement: its name and its beta at every (incidence, view) of the table.
struct MeasuredFit {
  std::string name;
  InplaneCurves beta;
};

// The RGB space of a measured table's values: its comment line "# colour_space: camera" or
// "# colour_space: srgb" (linear sRGB); unknown without one.
enum class MeasuredColourSpace { kUnknown, kCamera, kSrgb };
std::string colour_space_name(MeasuredColourSpace c);  // "unknown", "camera", "srgb"
// "camera" or "srgb"; weft::Error naming 'file' and 'field' otherwise.
MeasuredColourSpace parse_colour_space(const std::string& text, const std::string& file,
                                       const std::string& field);
// Whether a figure that includes the colour's level (absolute) compares with the models' linear
// sRGB: only a measurement in linear sRGB. Per-channel gains (the shape, the paper's
// normalization) absorb the diagonal part of a change of RGB space, so those stay comparable.
inline bool absolute_comparable(MeasuredColourSpace c) {
  return c == MeasuredColourSpace::kSrgb;
}
// Why not, in words ("not comparable: the measurement is in camera RGB, the models in linear
// sRGB"); empty when comparable.
std::string not_comparable_note(MeasuredColourSpace c);

struct MeasuredInplane {
  std::string file;
  MeasuredColourSpace colour_space = MeasuredColourSpace::kUnknown;
  std::vector<MeasuredCurve> curves;  // by increasing theta_i; beta: the reference fit, "nbrdf"
  // Other fits of the same measurement, where the table has them (beta = pi f_r of its sgd_fr_*
  // and abc_fr_* columns): what the measurement's own spread is judged by.
  std::vector<MeasuredFit> other_fits;
};

// Every fit of the measurement: the reference ("nbrdf", MeasuredCurve::beta) first, then the
// others.
std::vector<MeasuredFit> measured_fits(const MeasuredInplane& measured);

// The limits of a measured table, checked before what they bound is read (a table of 0.5 degree
// steps over the whole plane fits them): its size on disk, its incidences, its views per
// incidence and its values (beta of a fabric is of order 1; the shiniest bundled satin peaks at
// about 230).
inline constexpr uintmax_t kMaxMeasuredBytes = 16u << 20;
inline constexpr size_t kMaxMeasuredIncidences = 180;
inline constexpr size_t kMaxMeasuredViews = 360;
inline constexpr double kMaxMeasuredBeta = 1e6;

// Reads a table in the format of materials/data/measured/*/inplane.csv: optional comment lines
// starting with '#' or '"#' (one of them may be "# colour_space: camera|srgb"), a header naming at
// least theta_i_deg, theta_o_deg, nbrdf_beta_R, nbrdf_beta_G, nbrdf_beta_B, and one row per
// (theta_i, theta_o) with theta_o < 0 on the mirror side (that table's convention; flipped here).
// The optional columns sgd_fr_R/G/B and abc_fr_R/G/B (each fit all three or none) are kept as
// other_fits. weft::Error naming the file and the column (or line) on a missing file or column, a
// non-number, a negative, non-finite or absurd (> kMaxMeasuredBeta) beta, a column that is zero at
// every row, an angle out of range, a duplicate row, or a table over the limits above.
MeasuredInplane read_measured_inplane(const std::filesystem::path& path);

// The bundled MERL red fabric (materials/data/measured/merl-red-fabric/inplane.csv), found in the
// source tree or the installed tree; weft::Error listing the places tried.
std::filesystem::path bundled_measured_inplane();

}  // namespace weft
