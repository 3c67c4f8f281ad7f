#pragma once
// How far apart two BSDF tables are, in the numbers a user of a gonioreflectometer looks at:
// relative RMS and largest relative difference (of table B against the reference A), overall and
// split into reflection (light and view on one side) and transmission, and in-plane curves of the
// radiance coefficient beta = pi f at given incidences in the warp (x z) and weft (y z) planes.
//
// Both tables are read as the renderer reads them (table_reader.h: interpolated, with the sheen
// of a table that holds one), so tables of other resolutions compare too; the differences are taken
// at the cell centres of the finer grid and weighted by D_i D_o (the cosine-weighted cell areas),
// which makes rel_rms an energy-weighted measure: noise in cells that hold no light does not
// dominate it. max_rel counts cells whose reference value is at least 'significant' times the
// reference's mean (smaller ones are noise-dominated).
#include <string>
#include <vector>

#include "weft/materials/bsdf_table.h"

namespace weft {

struct TableDifference {
  double rel_rms = 0;  // sqrt(sum (b - a)^2 D_i D_o) / sqrt(sum a^2 D_i D_o), all channels
  double max_rel = 0;  // max |b - a| / a over significant cells and channels
  size_t cells = 0;    // cell pairs compared
  // sqrt(sum (b - a)^2 D_i D_o / (channels sum D_i D_o)): the difference in units of f.
  double abs_rms = 0;
  // False where the reference holds no light on this side (an opaque reference's transmission):
  // no relative difference is defined there, and rel_rms and max_rel are NaN rather than a 0
  // that reads as a perfect match; abs_rms says how much light B has there.
  bool reference_has_light = true;
};

struct InPlaneCurve {
  double light_zenith_deg = 0;
  double plane_azimuth_deg = 0;         // 0: the warp plane (x z), 90: the weft plane (y z)
  std::vector<double> view_zenith_deg;  // > 0 on the mirror side (the paper's Fig. 7)
  std::vector<std::vector<double>> beta_a, beta_b;  // [view][channel], beta = pi f
};

struct TableComparison {
  TableDifference overall, reflection, transmission;
  std::vector<InPlaneCurve> curves;
  double in_plane_rel_rms = 0;  // over every curve point and channel, against A; NaN where A's
                                // curves hold no light (undefined, as a side's rel_rms)
};

struct CompareOptions {
  double significant = 0.01;
  std::vector<double> light_zenith_deg = {0, 30, 60};
  std::vector<double> plane_azimuth_deg = {0, 90};
  double view_step_deg = 5, view_max_deg = 85;
};

// A reference of no light (every value 0) has no relative difference to measure against: every
// comparison would read 0, identical. weft::Error naming 'file' and "values" then.
void check_compare_reference(const TabulatedBsdfTable& a, const std::string& file);

// Throws weft::Error when the tables differ in channel count or kind, or the reference A holds
// no light (check_compare_reference).
TableComparison compare_tables(const TabulatedBsdfTable& a, const TabulatedBsdfTable& b,
                               const CompareOptions& options = {});

// The in-plane curves as CSV: light_zenith_deg, plane_azimuth_deg, view_zenith_deg, then
// a_<channel>, b_<channel> for each channel name of the tables.
std::string in_plane_csv(const TableComparison& c, const std::vector<std::string>& channel_names);

}  // namespace weft
