#pragma once
// Plain-weave patch generator: warp yarns along x, weft yarns along z, the patch in the xz plane
// with y up (glTF's convention). Each yarn is a tube of circular cross-section around a
// sinusoidal over/under centre line; crossing yarns touch. Written as glTF with positions,
// normals, TANGENTS along the yarn, UVs (u along the yarn, v around it) and two materials, "warp"
// and "weft". Lengths in the parameters are millimetres; the glTF is in metres. Deterministic.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "weft/scenes/mesh.h"

namespace weft {

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
