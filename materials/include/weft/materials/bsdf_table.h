#pragma once
// Tabulated 4-D BSDF tables (fiber and fabric BSDFs baked by the fabric plugin, or analytic
// references) and their OpenEXR file format.
//
// Parameterization: each of wi and wo is binned on the equal-area octahedral square
// (core/sphere_mapping.h) at R x R bins over the FULL sphere (light may arrive from behind and
// transmission is included), so every bin covers the solid angle 4 pi / R^2. Directions are in
// the local frame x = tangent (fiber / yarn / warp axis), y = binormal, z = normal.
// Values: f in 1/sr (BSDF without cosine), indexed [wi_bin][wo_bin][channel]; bin index =
// y * R + x for the square cell (x, y). Every table, whoever made it, stores the same quantity,
// the COSINE-WEIGHTED average over the (wi bin, wo bin) cell pair
//   f[i][o] = int_{C_i} int_{C_o} f |cos theta_i| |cos theta_o| dwo dwi / (D_i D_o),
//   D_k = int_{C_k} |cos theta| dw   (OctahedralGrid::cosine_weighted_areas),
// which makes f[i][o] D_i D_o exactly the energy the cell pair carries (docs/fiber-bsdf.md).
//
// File: one scanline OpenEXR image, height R^2 (row = wi bin), width R^2 (column = wo bin), FLOAT
// channels R,G,B or w390..w710 (one per 10 nm band), ZIP compression (lossless, so round trips
// are bit-exact). Header attributes:
//   weft_format_version (int) = 2, parameterization (string) = kParameterization,
//   cell_average (string) = "cosine-weighted" (the stored quantity; readers reject any other),
//   resolution (int) = R, bands (string) = "rgb" | "390:710:10", units (string) = "1/sr",
//   kind (string) = "fiber" | "fabric", values_fnv1a64 (string, 16 hex digits) = checksum() of the
//   values (EXR itself has no checksum: an uncompressible table is stored raw, and damaged bytes
//   would read back as other finite numbers),
//   and every entry of 'metadata' as a string attribute (conventional keys: spec_hash, photons,
//   seed, program_version).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/vec.h"

namespace weft {

// The ONE mapping between directions and bins, shared by table construction, eval, sample and
// pdf (so they cannot disagree about which bin a direction falls in).
struct OctahedralGrid {
  int resolution = 0;  // R

  int bins() const { return resolution * resolution; }
  // Direction -> point of the unit square (equal-area octahedral map).
  static Vec2 to_square(const Vec3& d);
  static Vec3 to_direction(Vec2 p);
  // The bin holding square point p / direction d.
  int bin_of_square(Vec2 p) const;
  int bin_of(const Vec3& d) const { return bin_of_square(to_square(d)); }
  Vec3 bin_center(int bin) const;
  // Cell (x, y) possibly outside [0, R)^2 by one -> the bin across the octahedral fold: the
  // square's edges fold onto themselves ((1, v) and (1, -v) are the same direction in [-1,1]^2),
  // so crossing an edge mirrors the other coordinate; the four corners meet at the south pole.
  int wrapped_bin(int x, int y) const;

  // Bilinear interpolation footprint of square point p over the 4 nearest bin centres.
  struct Footprint {
    int bin[4];
    double weight[4];
  };
  Footprint bilinear(Vec2 p) const;

  // D_k = integral over bin k of |cos theta| d omega (exact, to rounding): the weight of a
  // cosine-weighted cell average, and sum_k D_k = 2 pi.
  std::vector<double> cosine_weighted_areas() const;
  // The same split at the horizon: upper = int max(cos theta, 0) d omega and lower =
  // int max(-cos theta, 0) d omega over bin k. Bins along the square's inner diamond straddle the
  // horizon and have both parts.
  struct CosineWeightedArea {
    double upper = 0, lower = 0;
    double total() const { return upper + lower; }
  };
  std::vector<CosineWeightedArea> cosine_weighted_areas_by_side() const;
};

// f(wo, wi) -> one value per channel (written into 'values'); must be thread-safe.
using TableFunction = std::function<void(const Vec3& wo, const Vec3& wi, std::span<double> values)>;

struct TabulatedBsdfTable {
  // 2: the stored quantity is stated (cell_average). Version 1 files are read when their quantity
  // is known to be the cosine-weighted average (fiber bakes, whose "definition" says so); plain
  // solid-angle averages of version 1 ('weft table bake') are rejected with a request to re-bake.
  static constexpr int kFormatVersion = 2;
  static constexpr const char* kCellAverage = "cosine-weighted";
  static constexpr const char* kParameterization =
      "equal-area-octahedral x equal-area-octahedral, local frame x=t y=b z=n";
  static constexpr const char* kUnits = "1/sr";
  static constexpr const char* kSpectralBands = "390:710:10";

  int resolution = 0;          // R: bins per side of the octahedral square, for each direction
  int channels = 3;            // 3 (RGB) or kNumBands (33 spectral bands 390..710 nm)
  std::string kind = "fiber";  // "fiber" | "fabric"
  std::map<std::string, std::string> metadata;  // spec_hash, photons, seed, program_version, ...
  std::vector<float> values;                    // [wi_bin][wo_bin][channel]

  OctahedralGrid grid() const { return {resolution}; }
  int bins() const { return resolution * resolution; }
  size_t index(int wi_bin, int wo_bin, int channel) const {
    return (static_cast<size_t>(wi_bin) * static_cast<size_t>(bins()) +
            static_cast<size_t>(wo_bin)) *
               static_cast<size_t>(channels) +
           static_cast<size_t>(channel);
  }
  float at(int wi_bin, int wo_bin, int channel) const {
    return values[index(wi_bin, wo_bin, channel)];
  }
  // 64-bit FNV-1a over the values' bytes (IEEE binary32, little-endian, in index order), as 16
  // lower-case hex digits.
  std::string checksum() const;
  // "rgb" or "390:710:10"; channel names "R","G","B" or "w390".."w710".
  std::string bands() const;
  std::vector<std::string> channel_names() const;

  // Throws weft::Error(file, field, ...) unless the table is well formed: resolution in
  // [1, kMaxResolution], channels 3 or 33, kind known, size matches, every value finite and >= 0,
  // metadata keys not reserved.
  // R = 64 already means 16.8 M cell pairs (200 MB as RGB floats, ~700 MB while preparing).
  static constexpr int kMaxResolution = 64;
  // Attribute names the format or OpenEXR itself uses; metadata may not use them.
  static bool is_reserved_attribute(const std::string& name);
  void validate(const std::string& file_for_errors) const;

  // Cosine-weighted cell averages of an analytic f by stratified sampling: for each (wi bin,
  // wo bin) pair, 'samples_per_cell' pairs of directions, each Latin-hypercube stratified within
  // its cell (in the equal-area square, i.e. uniform in solid angle), averaged with the weights
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

  // Writes the OpenEXR file atomically (a complete file or none). Throws weft::Error.
  void write_exr(const std::filesystem::path& path) const;
  // Reads and validates an OpenEXR table; throws weft::Error naming the file and the attribute or
  // field at fault (missing file, not EXR, truncated or corrupt data, wrong version, sizes,
  // channels, non-finite or negative values).
  static TabulatedBsdfTable read_exr(const std::filesystem::path& path);

  // Where the light arriving in one wi bin goes, per channel: the directional albedo
  // rho(w_i) = int f(w_i, w_o) |cos theta_o| d w_o over all exits, averaged over the wi bin with
  // weight |cos theta_i| (the weighting of the cells, docs/fiber-bsdf.md "What a table cell
  // stores", which makes the total exact for a table of such cells: sum_o f[i][o] D_o).
  // reflectance counts exits on the side of the surface the light came from (cos theta_o and
  // cos theta_i of one sign), transmittance the others. A bin straddling the horizon holds one
  // average for both sides, so each side of it gets its share of the bin's projected solid angle:
  // the split is approximate in those bins, the total is not.
  struct DirectionalAlbedo {
    std::vector<double> reflectance, transmittance;  // per channel
    double total(int channel) const { return reflectance[channel] + transmittance[channel]; }
  };
  DirectionalAlbedo directional_albedo(int wi_bin) const;
};

}  // namespace weft
