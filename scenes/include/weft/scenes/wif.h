#pragma once
// WIF weaving drafts (Weaving Information File 1.1, 1997): the plain-text interchange format of
// weaving software, a Windows-INI file. Section and key names are case-insensitive; lists are
// "index=value[,value...]"; ';' starts a comment line.
//
// Read: [WEAVING] Shafts, Treadles, Rising Shed; [WARP]/[WEFT] Threads, Units (Decipoints |
// Inches | Centimeters | Millimeters), Spacing, Thickness, Color; [THREADING] (warp thread ->
// shafts); [TIEUP] (treadle -> shafts) + [TREADLING] (pick -> treadles), or [LIFTPLAN] (pick ->
// lifted shafts); per-thread overrides [WARP SPACING] [WEFT SPACING] [WARP THICKNESS]
// [WEFT THICKNESS]; colours [COLOR PALETTE] (Range) + [COLOR TABLE] + [WARP COLORS]/[WEFT COLORS].
//
// Interlacing: warp i lies over pick j when one of its shafts is lifted on pick j (Rising Shed =
// yes, the default); with a sinking shed the listed shafts sink, so the warp is over where none of
// its shafts is listed. Every thread 1..Threads must appear exactly once in THREADING and in
// TREADLING/LIFTPLAN (an empty value means no shaft / no treadle); a treadle missing from TIEUP
// lifts nothing. Every problem is a weft::Error naming the file, section and key; counts are
// checked against limits before anything is sized by them. Refused too: a NUL byte (not a text
// file), a spacing or thickness below kWifMinThreadMm, and a draft where no thread interlaces
// (interlacing(): every crossing on one side).
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "weft/scenes/weave_pattern.h"

namespace weft {

struct WifThread {
  std::vector<int> shafts;  // warp: the shafts it is threaded on; weft: the shafts lifted (1-based)
  double spacing_mm = 0;    // centre-to-centre distance allotted to the thread
  double thickness_mm = 0;  // the draft's thread thickness (drawn width)
  std::array<double, 3> rgb{0.5, 0.5, 0.5};  // colour in [0, 1] (the palette's Range mapped)
};

struct WifDraft {
  std::string source;  // file name, for messages
  int shafts = 0;
  int treadles = 0;  // 0 when the draft has a LIFTPLAN
  bool rising_shed = true;
  std::vector<WifThread> warp;  // in threading order
  std::vector<WifThread> weft;  // in treadling order: shafts = lifted on this pick
  std::string weft_source;      // "TREADLING" or "LIFTPLAN"
  // Whether the draft states a colour ([WARP]/[WEFT] Color, [WARP COLORS], [WEFT COLORS]); else
  // every thread has WifThread's default grey.
  bool colours_given = false;

  Interlacing interlacing() const;
};

// Limits checked before sizing anything by a count in the file.
inline constexpr int kWifMaxThreads = 20000;  // per direction
inline constexpr int kWifMaxShafts = 4096;    // and treadles
inline constexpr double kWifMaxCells = 2e7;   // warp threads x picks (the matrix)
inline constexpr size_t kWifMaxFileBytes = 64 << 20;
inline constexpr size_t kWifMaxSections = 1024;
inline constexpr size_t kWifMaxSectionKeys = 1 << 16;  // [COLOR TABLE] has up to 65536 entries
inline constexpr size_t kWifMaxKeys = 1 << 20;         // in the whole file
// A spacing or thickness below this is thinner than one fiber (a unit or export error).
inline constexpr double kWifMinThreadMm = 1e-3;

// 'source' names the text in errors.
WifDraft parse_wif(std::string_view text, const std::string& source);
WifDraft read_wif(const std::filesystem::path& path);

}  // namespace weft
