#pragma once
// The weave table: how a fabric table's scattering varies over one repeat of the weave. Per
// position cell of the repeat, a per-channel modulation of the fabric table at a coarse angular
// resolution (docs/fabric-bsdf.md "The weave level"):
//   f(x, wo, wi) = f_table(wo, wi) * m(cell(x), coarse_bin(wi), coarse_bin(wo), channel).
// The ray trace makes it (m = what it booked for exits through position cell p and the coarse
// cell pair, over the mean over p of the same; 1 where that mean is 0), so the mean of m over the
// cells is 1 and a repeat averaged is exactly the table.
//
// Positions: u along the warp (the table's x), v along the table's y (= n x warp); cell
// (iu, iv) covers [iu, iu + 1) / positions_u of the repeat along u, pos = iv * positions_u + iu.
// Coarse bins: the DirectionGrid (core/direction_grid.h) at 'resolution', in the table's frame.
//
// File: one scanline OpenEXR image, width 2 R^2 (column = wo bin), height
// positions_u * positions_v * 2 R^2 (row = pos * 2 R^2 + wi bin), FLOAT channels as the fabric
// table's (R,G,B or w390..w710), ZIP (lossless). Header attributes: weft_format_version (int) = 1,
// kind (string) = "fabric-weave", resolution (int) = R, positions (string) = "8x8" (u x v),
// repeat_m (string) = "0.00072 0.00072" (metres along u and v, printed to round-trip), bands
// (string) = "rgb" | "390:710:10", values_fnv1a64 (string) = checksum(), and every entry of
// 'metadata' as a string attribute (e.g. the fabric table's checksum, seed).
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace weft {

struct WeaveTable {
  static constexpr int kFormatVersion = 1;
  static constexpr const char* kKind = "fabric-weave";
  static constexpr int kMaxResolution = 32;  // as TabulatedBsdfTable's
  static constexpr int kMaxPositions = 64;   // cells per side of the repeat
  // At most 2^28 values (1 GiB of floats) in all.
  static constexpr size_t kMaxValues = size_t{1} << 28;

  int resolution = 0;                     // coarse DirectionGrid R of the modulation (e.g. 4)
  int channels = 3;                       // the fabric table's channels (3 or kNumBands)
  int positions_u = 0, positions_v = 0;   // cells over one repeat; u along the warp (table x),
                                          // v along the table's y (= n x warp)
  double repeat_u_m = 0, repeat_v_m = 0;  // the repeat's size, metres, along u and v
  std::map<std::string, std::string> metadata;  // fabric table checksum it belongs to, seed, ...
  std::vector<float> modulation;  // [pos][wi_bin][wo_bin][channel], pos = iv * positions_u + iu

  int bins() const { return 2 * resolution * resolution; }  // coarse bins per direction
  int positions() const { return positions_u * positions_v; }
  size_t index(int pos, int wi_bin, int wo_bin, int channel) const {
    const size_t n = static_cast<size_t>(bins());
    return ((static_cast<size_t>(pos) * n + static_cast<size_t>(wi_bin)) * n +
            static_cast<size_t>(wo_bin)) *
               static_cast<size_t>(channels) +
           static_cast<size_t>(channel);
  }
  // "rgb" or "390:710:10".
  std::string bands() const;
  // 64-bit FNV-1a over the values' bytes, as TabulatedBsdfTable::checksum.
  std::string checksum() const;
  // Attribute names the format or OpenEXR itself uses; metadata may not use them.
  static bool is_reserved_attribute(const std::string& name);

  // Throws weft::Error(file, field, ...) unless well formed: resolution in [1, kMaxResolution],
  // channels 3 or 33, positions in [1, kMaxPositions] per side, repeat sizes finite and > 0,
  // at most kMaxValues values and exactly as many as the sizes say, every value finite and >= 0,
  // metadata keys not reserved.
  void validate(const std::string& file_for_errors) const;
  // Writes the OpenEXR file atomically (a complete file or none). Throws weft::Error.
  void write_exr(const std::filesystem::path& path) const;
  // Reads and validates; weft::Error naming the file and the attribute or field at fault
  // (missing file, not EXR, wrong kind or version, sizes, channels, non-finite or negative
  // values, checksum). Sizes are checked against the file before anything is allocated.
  static WeaveTable read_exr(const std::filesystem::path& path);
};

}  // namespace weft
