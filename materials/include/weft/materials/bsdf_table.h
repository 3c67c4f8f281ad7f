#pragma once
// Tabulated 4-D BSDF tables (fiber and fabric BSDFs baked by the fabric plugin, or analytic
// references) and their OpenEXR file format.
//
// Parameterization: each of wi and wo is binned on the project's DirectionGrid
// (core/direction_grid.h) at R x R bins per hemisphere, 2 R^2 over the FULL sphere (light may
// arrive from behind and transmission is included), every bin of solid angle 2 pi / R^2 and none
// straddling the horizon. Directions are in the local frame x = tangent (fiber / yarn / warp
// axis), y = binormal, z = normal.
// Values: f in 1/sr (BSDF without cosine), indexed [wi_bin][wo_bin][channel] with the grid's bin
// indices. Every table, whoever made it, stores the same quantity,
// the COSINE-WEIGHTED average over the (wi bin, wo bin) cell pair
//   f[i][o] = int_{C_i} int_{C_o} f |cos theta_i| |cos theta_o| dwo dwi / (D_i D_o),
//   D_k = int_{C_k} |cos theta| dw   (DirectionGrid::cosine_weighted_areas),
// which makes f[i][o] D_i D_o exactly the energy the cell pair carries (docs/fiber-bsdf.md).
//
// File: one scanline OpenEXR image, height 2 R^2 (row = wi bin), width 2 R^2 (column = wo bin),
// FLOAT channels R,G,B or w390..w710 (one per 10 nm band), ZIP compression (lossless, so round
// trips are bit-exact). Header attributes:
//   weft_format_version (int) = kFormatVersion, parameterization (string) = kParameterization,
//   cell_average (string) = "cosine-weighted" (the stored quantity; readers reject any other),
//   resolution (int) = R, bands (string) = "rgb" | "390:710:10", units (string) = "1/sr",
//   kind (string) = "fiber" | "fabric", values_fnv1a64 (string, 16 hex digits) = checksum() of the
//   values (EXR itself has no checksum: an uncompressible table is stored raw, and damaged bytes
//   would read back as other finite numbers),
//   and every entry of 'metadata' as a string attribute (conventional keys: spec_hash, photons,
//   seed, program_version); since version 4, optionally the analytic surface lobe the cells
//   include (surface_lobe.h: "surface_lobe", "surface_lobe_distribution", "surface_lobe_alpha",
//   "surface_lobe_ior"). Since version 5, optionally a fabric table's sheen in half-vector space
//   (half_vector_lobe.h: "sheen", "sheen_h_resolution", "sheen_window"): the image is then wider,
//   each row's columns past the 2 R^2 cells holding that light bin's W x W window bins, and
//   values_fnv1a64 covers every pixel. Since version 6, optionally "sheen_fresnel_ior"; since
//   version 7, optionally "sheen_light_resolution" R_l = 2 R or 4 R, each row then holding the
//   windows of the (R_l / R)^2 light bins nested in its bin. Version 3 to 6 files still load.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/progress.h"
#include "weft/core/vec.h"
#include "weft/materials/half_vector_lobe.h"
#include "weft/materials/surface_lobe.h"

namespace weft {

// The interpolation of a table between its cells, shared by every reader: bilinear in each
// direction within its own hemisphere (DirectionGrid::bilinear), so f(wo, wi) blends up to 16 cell
// pairs. Calls add(wi_bin, wo_bin, weight) for each pair of non-zero weight.
template <class Add>
void for_each_interpolated_cell(const DirectionGrid& grid, const Vec3& wo, const Vec3& wi,
                                Add&& add) {
  const auto fo = grid.bilinear(DirectionGrid::to_chart(wo));
  const auto fi = grid.bilinear(DirectionGrid::to_chart(wi));
  for (int a = 0; a < 4; ++a) {
    if (fi.weight[a] == 0) continue;
    for (int b = 0; b < 4; ++b) {
      const double w = fi.weight[a] * fo.weight[b];
      if (w != 0) add(fi.bin[a], fo.bin[b], w);
    }
  }
}

// f(wo, wi) -> one value per channel (written into 'values'); must be thread-safe.
using TableFunction = std::function<void(const Vec3& wo, const Vec3& wi, std::span<double> values)>;

struct TabulatedBsdfTable {
  // 3: the hemispherical DirectionGrid (versions 1 and 2 used an octahedral grid whose bins
  // straddled the horizon; they are refused with a request to re-bake). Since version 2 the
  // stored quantity is stated (cell_average). 4: an optional analytic surface lobe beside the
  // cells (surface_lobe); version 3 tables have none and still load. 5: an optional sheen in
  // half-vector space beside the cells (sheen). 6: the sheen may hold its values over the fibers'
  // Fresnel reflectance (HalfVectorLobe::fresnel_ior); version 5 sheens have none. 7: the sheen's
  // light bins may be finer than the table's (HalfVectorLobe::light_resolution).
  static constexpr int kFormatVersion = 7;
  static constexpr int kOldestReadableVersion = 3;
  static constexpr const char* kCellAverage = "cosine-weighted";
  static constexpr const char* kParameterization =
      "equal-area hemispheres (octahedral, turned 45 deg; upper then lower) for wi and wo, local "
      "frame x=t y=b z=n";
  static constexpr const char* kUnits = "1/sr";
  static constexpr const char* kSpectralBands = "390:710:10";

  int resolution = 0;          // R: bins per side of the octahedral square, for each direction
  int channels = 3;            // 3 (RGB) or kNumBands (33 spectral bands 390..710 nm)
  std::string kind = "fiber";  // "fiber" | "fabric"
  std::map<std::string, std::string> metadata;  // spec_hash, photons, seed, program_version, ...
  std::vector<float> values;                    // [wi_bin][wo_bin][channel]
  // The analytic part of f the cells include (surface_lobe.h), if the table names one: a reader
  // may evaluate it exactly (f = cells less its cell averages, interpolated, + the lobe) or ignore
  // it (the cells are the whole f).
  std::optional<SurfaceLobe> surface_lobe;
  // A fabric table's first-surface reflection per light bin over a fine half-vector window
  // (half_vector_lobe.h), if it holds one: like the surface lobe, the cells include it.
  std::optional<HalfVectorLobe> sheen;

  DirectionGrid grid() const { return {resolution}; }
  int bins() const { return 2 * resolution * resolution; }
  size_t index(int wi_bin, int wo_bin, int channel) const {
    return (static_cast<size_t>(wi_bin) * static_cast<size_t>(bins()) +
            static_cast<size_t>(wo_bin)) *
               static_cast<size_t>(channels) +
           static_cast<size_t>(channel);
  }
  float at(int wi_bin, int wo_bin, int channel) const {
    return values[index(wi_bin, wo_bin, channel)];
  }
  // 64-bit FNV-1a over the values' bytes (IEEE binary32, little-endian, in index order), then the
  // sheen's values when there is one, as 16 lower-case hex digits.
  std::string checksum() const;
  // "rgb" or "390:710:10"; channel names "R","G","B" or "w390".."w710".
  std::string bands() const;
  std::vector<std::string> channel_names() const;

  // Throws weft::Error(file, field, ...) unless the table is well formed: resolution in
  // [1, kMaxResolution], channels 3 or 33, kind known, size matches, every value finite and >= 0,
  // metadata keys not reserved.
  // R = 32 already means 2048 bins per direction, 4.2 M cell pairs (50 MB as RGB floats).
  static constexpr int kMaxResolution = 32;
  // Attribute names the format or OpenEXR itself uses; metadata may not use them.
  static bool is_reserved_attribute(const std::string& name);
  void validate(const std::string& file_for_errors) const;

  // Cosine-weighted cell averages of an analytic f by stratified sampling: for each (wi bin,
  // wo bin) pair, 'samples_per_cell' pairs of directions, each Latin-hypercube stratified within
  // its cell (in the equal-area chart, i.e. uniform in solid angle), averaged with the weights
  // |cos theta_i| |cos theta_o| (a ratio estimator: a constant f is reproduced exactly). Random
  // streams come from
  // (seed, wi bin, wo bin), so the result is the same at any thread count. 'progress' is called
  // on the calling thread between chunks of rows (stage "table"); returning false cancels with a
  // weft::Error (a partial table is of no use).
  static TabulatedBsdfTable from_function(int resolution, int channels, const TableFunction& f,
                                          int samples_per_cell, uint64_t seed = 0, int threads = 0,
                                          const ProgressCallback& progress = no_progress());

  // A table from sums of f |cos_i| |cos_o| d wi d wo over each cell pair, as a Monte Carlo
  // estimator of the integral gathers them (the fiber baker): divides by D_i D_o. 'weighted_sums'
  // is [wi_bin][wo_bin] for one channel; returns the cell averages in the same order.
  static std::vector<double> averages_from_weighted_sums(int resolution,
                                                         const std::vector<double>& weighted_sums);

  // The table without its surface lobe: the cells less the lobe's cell averages
  // (SurfaceLobe::cell_averages), the rest of f, which a reader that evaluates the lobe exactly
  // interpolates. Differences below float rounding of a cell (1e-6 of the lobe's value) are
  // rounding and become 0; a cell holding less than its lobe by more is an Error naming the cell
  // (such a table was not made by adding the lobe). A table without a lobe comes back as it is.
  // 'lobe_cells' (optional) receives the lobe's cell averages.
  TabulatedBsdfTable without_surface_lobe(const std::string& file_for_errors, int threads = 0,
                                          std::vector<double>* lobe_cells = nullptr) const;
  // Adds the lobe's cell averages to the cells and names the lobe (what a baker that left the
  // lobe's light out of its sums does). Error if the table has one already or the lobe's channels
  // differ. 'cells' (optional): lobe.cell_averages(grid()) already computed by the caller.
  void add_surface_lobe(const SurfaceLobe& lobe, int threads = 0,
                        const std::vector<double>* cells = nullptr);

  // The same for the sheen (HalfVectorLobe::cell_averages): the cells less the sheen's cell
  // averages, the sheen removed; an Error naming the cell where a cell holds less than its sheen
  // by more than float rounding. 'sheen_cells' (optional) receives them.
  TabulatedBsdfTable without_sheen(const std::string& file_for_errors, int threads = 0,
                                   std::vector<double>* sheen_cells = nullptr) const;
  // Adds the sheen's cell averages to the cells and keeps the sheen (the fabric ray trace, which
  // booked the sheen's light apart from the cells). Error if the table has one already or the
  // shapes differ.
  void add_sheen(HalfVectorLobe lobe, int threads = 0);

  // f(wo, wi) per channel, interpolated like the table material does (for_each_interpolated_cell);
  // 'out' holds 'channels' values.
  void interpolate(const Vec3& wo, const Vec3& wi, std::span<double> out) const;

  // Writes the OpenEXR file atomically (a complete file or none). Throws weft::Error.
  void write_exr(const std::filesystem::path& path) const;
  // Throws weft::Error(path, field, ...) unless a table can be written there: the name ends in
  // .exr (the only format written) and the folder exists. Commands call it before the work.
  static void check_output_path(const std::filesystem::path& path, const std::string& field);
  // Reads and validates an OpenEXR table; throws weft::Error naming the file and the attribute or
  // field at fault (missing file, not EXR, truncated or corrupt data, wrong version, sizes,
  // channels, non-finite or negative values).
  static TabulatedBsdfTable read_exr(const std::filesystem::path& path);

  // Where the light arriving in one wi bin goes, per channel: the directional albedo
  // rho(w_i) = int f(w_i, w_o) |cos theta_o| d w_o over all exits, averaged over the wi bin with
  // weight |cos theta_i| (the weighting of the cells, docs/fiber-bsdf.md "What a table cell
  // stores", which makes the total exact for a table of such cells: sum_o f[i][o] D_o).
  // reflectance counts exits on the side of the surface the light came from (cos theta_o and
  // cos theta_i of one sign), transmittance the others; no bin straddles the horizon, so the
  // split is as exact as the total.
  struct DirectionalAlbedo {
    std::vector<double> reflectance, transmittance;  // per channel
    double total(int channel) const { return reflectance[channel] + transmittance[channel]; }
  };
  DirectionalAlbedo directional_albedo(int wi_bin) const;
  // The same seen from one wo bin, as a renderer gathers it: int f(w_o, w_i) |cos theta_i| d w_i
  // over all arrivals (sum_i f[i][o] D_i), the radiance towards w_o under uniform unit radiance;
  // reflectance counts light arriving on w_o's side, transmittance light from the other side.
  // Equal to directional_albedo for a reciprocal table. The paper's summed fabric tables are
  // not: their fiber sits on top of the cloth, so nothing leaves below it (light from above is
  // never transmitted, directional_albedo's transmittance is 0), while light from below passes
  // through the fiber to a view from above (this one's transmittance is 0.6-0.8 for red cotton).
  DirectionalAlbedo directional_albedo_seen_from(int wo_bin) const;
  // The total albedo per channel, (1/pi) sum_i sum_o f[i][o] D_i D_o (D: the bins' cosine-weighted
  // areas, core/direction_grid.h). For a fiber table it is the fraction of the light hitting the
  // fiber that leaves it, at most 1: the bake's exit_fraction, which the bake states is the same
  // sum (fiber_table_bake.h FiberBandSummary::energy_table).
  std::vector<double> total_albedo() const;
};

}  // namespace weft
