#pragma once
// Shared by the weave generator's parts (weave.cpp: options, yarn paths, tubes; weave_fibers.cpp:
// fiber bundles; weave_gltf.cpp: output). Lengths in millimetres unless named otherwise.
#include <array>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "weft/core/vec.h"
#include "weft/scenes/weave.h"

namespace weft::detail {

inline constexpr double kMetresPerMm = 1e-3;

// The bundled red-cotton sample (scenes/examples/red-cotton-weave.json; sources in
// scenes/examples/README.md): a cotton poplin, warp Ne 50 at 120 ends/in, weft Ne 42 at 60
// picks/in, lens sections of the Peirce yarn area, warp closed, weft straight. Lengths in mm.
namespace red_cotton {
inline constexpr double kRedWarpSpacing = 0.2117, kRedWarpWidth = 0.2117,
                        kRedWarpThickness = 0.0959;
inline constexpr double kRedWeftSpacing = 0.4233, kRedWeftWidth = 0.2310,
                        kRedWeftThickness = 0.1047;
inline constexpr double kRedWarpCrimpShare = 1.0;
inline constexpr double kRedFiberRadiusUm = 8.0;
inline constexpr double kRedPacking = 0.55;
inline constexpr double kRedTwistPerMm = 1.0;
}  // namespace red_cotton

// One yarn of the sample: its axis, where it lies, and its crimped centre line.
struct YarnPath {
  bool warp = true;   // warp: along x, positioned along z; weft: along z, positioned along x
  int thread = 0;     // index in the repeat
  double centre = 0;  // lateral position of the centre line (z for warp, x for weft)
  ThreadSize size;
  double start = 0;              // along coordinate where the sample begins (-period/2)
  double period = 0;             // along the yarn
  std::vector<double> crossing;  // along coordinates of the crossing threads' centres, ascending
  std::vector<double> height;    // signed centre height at each crossing (+: this yarn over)

  Vec3 along() const { return warp ? Vec3{1, 0, 0} : Vec3{0, 0, 1}; }
  Vec3 across() const { return warp ? Vec3{0, 0, 1} : Vec3{1, 0, 0}; }
  // Lateral direction of the section: along x up (warp: +z, weft: -x).
  Vec3 lateral() const { return warp ? Vec3{0, 0, 1} : Vec3{-1, 0, 0}; }
  // Centre height and its slope at along coordinate s (any s: periodic).
  double height_at(double s, double* slope = nullptr) const;
  // Largest |slope| of the centre line.
  double max_slope() const;
};

struct Layout {
  Interlacing tile;             // the repeat tiled repeats_x by repeats_z
  std::vector<YarnPath> yarns;  // warps (tile order), then wefts
  double period_x = 0, period_z = 0;
  double warp_crimp_share = 0;
  int segments_per_crossing = 16;
  int sides = 16;
};

// Lens half-thickness at lateral offset l of a section w wide and t thick.
double lens_half_thickness(double w, double t, double l);

struct FiberSettings {
  double radius_mm = 0;
  int fibers_per_yarn = 0;  // 0: from packing
  double packing = 0;
  // Neither packing nor fibers per yarn given: where 'packing' (the default) does not fit a
  // section, that section takes the most fibers that do (the densest packing it admits).
  bool densest_if_needed = false;
  int plies = 1;
  double twist_per_mm = 0;     // signed, Z > 0
  double twist_angle_deg = 0;  // used when twist_per_mm is not given (then > 0)
  bool twist_from_angle = false;
  double ply_twist_per_mm = 0;
  // Fibers in sections perpendicular to the yarn's centre line (denser: the crimp does not tilt
  // one fiber against another) or in vertical sections like the tubes' (the bundle then stays
  // within the tube where the yarn slopes, which closely packed crossings need).
  bool perpendicular = true;
};

// Fills 'out' with the fibers of every yarn; per distinct yarn section the layout info.
// 'keep_going' is asked before each yarn (yarns done, yarns in all); false stops with 'out'
// partly filled.
void build_fibers(const Layout& layout, const FiberSettings& fs, FiberCurves& out,
                  std::vector<FiberLayoutInfo>& warp_info, std::vector<FiberLayoutInfo>& weft_info,
                  const std::function<bool(uint64_t, uint64_t)>& keep_going);

// The fibers and curve points build_fibers makes with these settings, from the yarns' bundles
// alone (no fiber placed): the same errors as build_fibers where a bundle does not fit.
struct FiberCount {
  double curves = 0, points = 0;
};
FiberCount count_fibers(const Layout& layout, const FiberSettings& fs);

// Distance between the segments p0-p1 and q0-q1 (any units).
double segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// A glTF document and its one binary buffer, shared by the legacy patch and woven samples.
struct GltfDocument {
  nlohmann::json doc;
  std::vector<uint8_t> bin;
};
// Triangle meshes (one glTF mesh each, material by TriangleMesh::material) or fiber curves (one
// node and mesh per yarn, one LINE_STRIP primitive per fiber), under a root node "patch".
// 'extras' goes to the document's extras.weft_weave; 'yarn_rgb' (optional, per yarn) to the
// yarn nodes' extras.
GltfDocument build_gltf(const std::vector<TriangleMesh>* meshes, const FiberCurves* fibers,
                        const nlohmann::json& extras,
                        const std::vector<std::array<double, 3>>& yarn_rgb);
std::string gltf_text(GltfDocument d);  // buffer embedded as base64
std::vector<uint8_t> glb_bytes(const GltfDocument& d);
// .gltf or .glb by extension, atomically.
void write_gltf(const std::filesystem::path& path, const GltfDocument& d);

// A sample's question "go on?" (done, total) at one stage of its making, put to 'progress':
// once it says stop, sample.cancelled is set and every later ask says stop too, so the sample is
// left partial. 'sample' and 'progress' must outlive it.
inline std::function<bool(uint64_t, uint64_t)> sample_asker(WovenSample& sample,
                                                            const ProgressCallback& progress,
                                                            std::string_view stage,
                                                            std::string_view unit) {
  return [&sample, &progress, stage, unit](uint64_t done, uint64_t total) {
    sample.cancelled = sample.cancelled || !progress({stage, done, total, unit});
    return !sample.cancelled;
  };
}

}  // namespace weft::detail
