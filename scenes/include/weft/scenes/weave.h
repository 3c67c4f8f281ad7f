#pragma once
// Woven samples: one repeat of a weave pattern (plain, twill, satin or a WIF draft) that tiles the
// plane, at yarn detail (closed tubes, triangles) or fiber detail (round curves), written as glTF.
//
// Frame (glTF's, metres): the cloth lies in the xz plane with its face side towards +y. Warp
// yarns run along x and sit side by side along z (warp i of the repeat at increasing z); weft
// yarns (picks) run along z and sit side by side along x (pick j at increasing x). The sample
// covers x in [-Px/2, Px/2] and z in [-Pz/2, Pz/2], Px = sum of the weft spacings times the
// repeats along x, Pz = sum of the warp spacings times the repeats along z, centred on y = 0.
// Everything is periodic with (Px, Pz): centre lines, cross-sections and fiber positions at x and
// x + Px coincide (fibers as a set: a fiber that leaves through x = +Px/2 continues as the fiber
// that enters at -Px/2 at the same point), so a renderer can wrap rays across the sides.
//
// Yarn model (all lengths in the vertical plane across the yarn, as in a micrograph of a cut):
// - Cross-section: a lens of width w and thickness t, half-thickness (t/2) cos(pi l / w) at
//   lateral offset l in [-w/2, w/2]: flattened, with pointed edges.
// - Centre line: height +-a at each crossing (+ where the yarn is over), joined by half cosines
//   (flat along floats): smooth, C1. With a_warp + a_weft = (t_warp + t_weft) / 2 crossing yarns
//   touch at the crossing's centre; lens sections and cosine transitions keep them apart
//   everywhere else when a_warp <= (t_weft / 2) R and a_weft <= (t_warp / 2) R, where R >= 1
//   depends on how much narrower the crossing yarn is than its spacing (R = 1 when w = spacing,
//   then the two yarns meet along their whole crossing: flattened against each other). The
//   share of the crimp the warp takes is a parameter; the generator checks every crossing.
// - Parallel neighbours never overlap: each yarn stays within its own spacing (w <= spacing).
// - Each yarn is one tube closed around its section; it ends at the sample's sides, where its
//   end ring is exactly the start ring of its periodic copy (so the tiled cloth is watertight;
//   no end caps, which would be faces inside the cloth).
// Fiber model: each yarn (or ply) is a bundle of round fibers on nested rings inside its section
// (rings are the section eroded step by step, corners rounded), fibers evenly spaced along each
// ring and carried around it by the twist (the idealised helical yarn, flattened), and where the
// section left inside the last ring is too thin for a ring, a straight core row (the yarn's axis
// does not turn); plies are discs carried around the yarn by the ply twist, their fibers on
// circles turning with the fiber twist. The section is perpendicular to the centre line (fibers
// of a yarn are parallel curves, so the crimp does not bring them closer: packing up to about
// 0.55 for red cotton); where that makes the bundle stand out of the tube into a crossing yarn
// (it is taller than the vertical lens by sqrt(1 + slope^2)), as with balanced crossings pressed
// together along their length, the generator falls back to vertical sections like the tubes'
// (spacings then grow with the slope: sparser). Ring and fiber spacings include the tilt of the
// fibers so that fibers keep 2 x radius apart; the generator measures the minimum distance
// between fiber segments of the whole sample, periodic copies included, and refuses a sample
// below it.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/mesh.h"
#include "weft/scenes/nonwoven.h"
#include "weft/scenes/weave_pattern.h"

namespace weft {

class ParamReader;
struct SceneDescription;

// ---------------------------------------------------------------------------------------------
// Woven samples.

// What the user chooses (CLI options, a sample description JSON): every field optional. Unset
// fields take the bundled red-cotton sample's values (red_cotton_weave_options()), except the
// thread sizes and crimp share of a WIF draft, which come from the draft (crimp: balanced).
struct WeaveOptions {
  std::optional<std::string> pattern;  // plain | twill:N/M | satin:N[/MOVE]; not with a WIF
  std::optional<std::string> wif;      // path of a WIF draft (its threads replace the pattern)
  std::optional<std::string> detail;   // yarn | fiber
  std::optional<int> repeats_x, repeats_z;
  std::optional<double> warp_spacing_mm, weft_spacing_mm;  // centre to centre
  std::optional<double> warp_width_mm, weft_width_mm;
  std::optional<double> warp_thickness_mm, weft_thickness_mm;
  // Fraction of each crossing's total crimp height (t_warp + t_weft) / 2 that the warp carries;
  // negative: balanced (each yarn wraps half the other's thickness).
  std::optional<double> warp_crimp_share;
  std::optional<int> segments_per_crossing;  // along a yarn, per crossing (tubes, polylines)
  std::optional<int> sides;                  // around a yarn tube
  // Fiber detail.
  std::optional<double> fiber_radius_um;
  // Per yarn section; unset: from the packing fraction. With neither given, each section takes the
  // default packing (red cotton's 0.55) where it fits and the densest packing it admits where not
  // (FiberLayoutInfo::default_packing, WeaveSummary::notes); a value given that does not fit is
  // an error naming it.
  std::optional<int> fibers_per_yarn;
  std::optional<double> packing;  // fiber area / yarn section area
  std::optional<int> plies;
  std::optional<double> twist_per_mm;      // fibers about their ply (or yarn) axis, Z > 0
  std::optional<double> twist_angle_deg;   // alternative: surface helix angle of the fibers
  std::optional<double> ply_twist_per_mm;  // plies about the yarn axis (plies > 1), S < 0
  // Nonwoven mats (pattern "nonwoven", nonwoven.h): only with that pattern.
  std::optional<double> areal_density_gsm;   // g/m^2
  std::optional<double> thickness_mm;        // of the mat; or:
  std::optional<double> solidity;            // fiber volume / mat volume (sets the thickness)
  std::optional<double> inclination_sd_deg;  // of the fibers out of the cloth plane
  std::optional<double> fiber_length_mm;     // each fiber straight, at most half the tile
  std::optional<double> tile_mm;             // side of the square tile (the period)
  std::optional<double> fiber_density_g_cm3;
  std::optional<uint64_t> seed;

  bool operator==(const WeaveOptions&) const = default;  // the same sample
};

// Reads a sample description (a JSON object whose keys are the `weft weave` option names without
// the leading dashes, see scenes/examples/red-cotton-weave.json); unknown keys are errors.
// Relative "wif" paths resolve against 'base_dir'. Only the keys present are set.
WeaveOptions read_weave_options(ParamReader& r, const std::filesystem::path& base_dir);
WeaveOptions read_weave_options(const std::filesystem::path& json_file);
// The bundled red-cotton sample's options, every value set (the defaults of `weft weave`).
WeaveOptions red_cotton_weave_options();
// 'base' with every field that 'given' sets replaced; setting one of a pair of alternatives
// (pattern / wif, fibers-per-yarn / packing, twist-per-mm / twist-angle-deg, thickness-mm /
// solidity) clears the other.
WeaveOptions overlay(WeaveOptions base, const WeaveOptions& given);

// Sizes of one thread, millimetres.
struct ThreadSize {
  double spacing_mm = 0, width_mm = 0, thickness_mm = 0;
};

struct FiberLayoutInfo {
  int fibers = 0;              // per yarn section
  double packing = 0;          // fiber area / section area
  double twist_per_mm = 0;     // effective (rounded so the sample stays periodic), outer ring
  double twist_angle_deg = 0;  // surface helix angle relative to the yarn axis
  // > 0 where the default packing (this value) did not fit and the section took the densest
  // packing that does (neither --packing nor --fibers-per-yarn given); 0: the packing asked for.
  double default_packing = 0;
};

struct WeaveSummary {
  std::string source;  // pattern or WIF file
  std::string detail;
  int warps = 0, wefts = 0;  // threads in one repeat
  int repeats_x = 1, repeats_z = 1;
  double repeat_x_mm = 0, repeat_z_mm = 0;  // one repeat
  double period_x_mm = 0, period_z_mm = 0;  // the sample (repeats included): wrap here
  double y_min_mm = 0, y_max_mm = 0;        // thickness range (surfaces, fibers with radius)
  double warp_crimp_share = 0;
  std::vector<int> floating_warps, floating_wefts;  // in the repeat, 0-based
  size_t triangles = 0, vertices = 0;
  size_t curves = 0, curve_segments = 0, curve_points = 0;
  std::vector<FiberLayoutInfo> warp_fibers, weft_fibers;  // per distinct thread size
  double min_fiber_distance_um = 0;                       // measured (fiber detail), centre lines
  std::string fiber_sections;  // "perpendicular" or "vertical" (fiber detail; see the top)
  // What the generator chose for the user, one sentence each (the densest packing that fits).
  std::vector<std::string> notes;
  std::optional<NonwovenSummary> nonwoven;  // a nonwoven mat's parameters and counts
  double seconds = 0;                       // generation time
};

struct WovenSample {
  std::vector<TriangleMesh> meshes;  // yarn detail: "warp" and "weft" (all yarns of each)
  FiberCurves fibers;                // fiber detail
  WeaveSummary summary;
  // Per yarn of the sample (warps first, then wefts): its colour from a WIF draft, for extras.
  std::vector<std::array<double, 3>> yarn_rgb;
  // The progress callback asked to stop: the sample is partial and must not be used.
  bool cancelled = false;
};

// Checks everything (Error naming the field, before anything large is allocated) and builds the
// sample. Deterministic: equal options give equal samples. A large sample takes minutes (a WIF
// draft of 160 threads at fiber detail: about 2 minutes; 5e7 triangles of yarn tubes or a
// nonwoven mat of 20 000 fibers: tens of seconds), so 'progress' is told as the work goes (after
// each yarn's fibers, every 64 k vertices of a yarn tube, before each fiber placement drawn in a
// mat, between slices of the fiber-distance check) and may stop it (WovenSample::cancelled).
WovenSample make_woven_sample(const WeaveOptions& options,
                              const ProgressCallback& progress = no_progress());

// The size of the sample make_woven_sample would build, from its options alone: the same checks
// (weft::Error naming the field) but no geometry, for memory estimates before anything is
// allocated. Yarn detail: its tubes' triangles and vertices exactly, with the tessellation they
// take; fiber detail: its fibers and curve points as estimated from the packing (the count the
// curve-point limit is checked on). A nonwoven mat: its curves as expected (nonwoven_sample_size),
// not made (the largest takes tens of seconds).
struct WovenSampleSize {
  std::string detail;
  int sides = 0, segments_per_crossing = 0;  // yarn detail's tessellation
  double triangles = 0, vertices = 0;
  double curves = 0, curve_points = 0, curve_segments = 0;
  // Woven fiber detail: the sections the fibers are predicted to end in ("perpendicular", or
  // "vertical" where those would bring fibers too close: WeaveSummary::fiber_sections) and the
  // curve points and segments the sample then holds, from its yarns' bundles (no fiber placed).
  // The packing estimate above can be twice as high where the sample falls back to vertical
  // sections; memory is estimated from these. A nonwoven mat: the same as above.
  std::string fiber_sections;
  double made_curve_points = 0, made_curve_segments = 0;
  // A nonwoven mat: the work of placing its fibers (NonwovenSize), which its making time follows
  // rather than its points.
  double placement_crossing_checks = 0, placement_copy_checks = 0;
};
WovenSampleSize woven_sample_size(const WeaveOptions& options);

// Minimum distance between centre-line segments of distinct fibers, periodic copies in x and z
// included, looked for within 'cutoff_m' with a uniform grid (not all pairs). Returns cutoff_m
// when no two segments come closer. 'keep_going', when given, is asked between slices of the grid's
// cells (with the cells done and their total); once it says stop, the search ends and returns what
// it found so far.
double min_fiber_distance(const FiberCurves& fibers, double period_x_m, double period_z_m,
                          double cutoff_m,
                          const std::function<bool(uint64_t, uint64_t)>& keep_going = {});

// glTF 2.0 of the sample (metres). Yarn detail: meshes "warp_yarns"/"weft_yarns" (triangles with
// POSITION, NORMAL, TANGENT along the yarn, TEXCOORD_0 with u along the yarn) under node "patch".
// Fiber detail: one node and mesh per yarn ("warp_3", "weft_0", ...) under node "patch"; every
// fiber is one primitive of mode LINE_STRIP (3) with POSITION (VEC3 float, metres) and the custom
// attribute _RADIUS (SCALAR float, metres, one per point), material "warp" or "weft". A line
// strip cannot hold several fibers without joining them, hence one primitive per fiber. The
// document's extras.weft_weave holds the summary (periods, counts, parameters).
std::string woven_to_gltf(const WovenSample& sample);
std::vector<uint8_t> woven_to_glb(const WovenSample& sample);
// .gltf (buffer embedded as base64) or .glb by extension, atomically.
void write_woven(const std::filesystem::path& path, const WovenSample& sample);
// The summary as JSON (what `weft weave --json` prints).
std::string weave_summary_json(const WeaveSummary& summary, const std::string& output);
// A scene description holding the fiber-detail sample of 'options' (detail forced to fiber) as
// one curve set named 'object' (materials "warp" and "weft" left to the caller), for tests and
// benchmarks that render a fiber patch.
SceneDescription fiber_patch_description(WeaveOptions options, const std::string& source,
                                         const std::string& object);
// Copies of a periodic sample side by side, for renderers that need more cloth than one repeat:
// copy (i, k), shifted by (i Px, k Pz) (the sample's periods, summary) for i in [-half_x, half_x]
// and k in [-half_z, half_z], is copy number q = (2 half_z + 1) (i + half_x) + (k + half_z). At
// fiber detail copy q is curve set q (fiber c of the sample in it is fiber id q * curves + c,
// RenderScene numbering fibers set by set); at yarn detail copy q of the sample's mesh m is mesh
// m * copies + q. No materials are bound. weft::Error naming 'source' when the sample has no
// geometry or no period, or half_x, half_z lie outside [0, 64]. 'instanced' (yarn detail): the
// sample's meshes are stored once and placed at every copy by SceneDescription::mesh_shifts
// (copy q at mesh_shifts[q]; RenderScene traces them as instances, a hit's shape is mesh m), the
// memory of one repeat instead of (2 half_x + 1) (2 half_z + 1); fibers are copied either way.
SceneDescription tiled_woven_description(const WovenSample& sample, int half_x, int half_z,
                                         const std::string& source, bool instanced = false);
// The same, the fibers' copies made a slice of points at a time with 'progress' told (stage
// "scene copies") and asked between slices (near the limit of 3e7 points, nine copies took tens
// of seconds unpolled); nothing when it said stop. The same bits as the call above.
std::optional<SceneDescription> tiled_woven_description(const WovenSample& sample, int half_x,
                                                        int half_z, const std::string& source,
                                                        bool instanced,
                                                        const ProgressCallback& progress);

// ---------------------------------------------------------------------------------------------
// The open-mesh plain-weave patch of earlier versions (circular tubes around sinusoidal centre
// lines, 'yarns' per direction, centred, not periodic): kept for the benchmarks and tests that
// use it. Same frame and glTF layout as yarn detail above.

struct WeaveParams {
  std::string pattern = "plain";
  int yarns = 8;  // per direction
  double yarn_radius_mm = 0.1;
  double spacing_mm = 0.5;   // between neighbouring parallel yarns
  int segments = 64;         // along each yarn
  int sides = 8;             // around each yarn
  double amplitude_mm = -1;  // of the centre line; < 0: the yarn radius (crossings touch)
};

// Checks the parameters (Error naming the field) and returns the two meshes, "warp" and "weft".
std::vector<TriangleMesh> make_weave(const WeaveParams& params);
// The glTF document: .gltf text with the buffer embedded (base64) or .glb bytes.
std::string weave_to_gltf(const WeaveParams& params);
std::vector<uint8_t> weave_to_glb(const WeaveParams& params);
// Writes .gltf or .glb (by extension) atomically.
void write_weave(const std::filesystem::path& path, const WeaveParams& params);

}  // namespace weft
