#pragma once
// The glTF asset weft export writes, shared by the .gltf / .glb writer (one sample quad) and the
// .html preview (a cushion and a draped cloth): meshes carrying the one fitted material.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "weft/exchange/export_report.h"
#include "weft/exchange/gltf_material.h"

namespace weft::gltf_detail {

// One triangle mesh in glTF's frame (y up, metres), placed by 'translation_m'.
struct GltfMesh {
  std::string name;
  std::vector<float> positions_m, normals, uvs;  // 3, 3, 2 per vertex
  std::vector<uint32_t> indices;                 // triangles
  std::array<double, 3> translation_m{0, 0, 0};
  size_t vertices() const { return positions_m.size() / 3; }
};

// The export's sample: 1 m x 1 m in the x-z plane, facing +y.
GltfMesh sample_quad();

// The asset's bytes: binary glTF when 'glb', else JSON with the buffer as a data URI. Every
// mesh carries material 0, the fit's, whose extras hold the fit's error and 'name'.
std::string gltf_asset(const GltfFit& fit, const std::string& name, double epsilon_per_sr,
                       const std::vector<GltfMesh>& meshes, bool glb, const std::string& path);

// What the material carries and drops, and the fit's figures, for the command to print.
ExportReport gltf_report(const GltfFit& fit);

}  // namespace weft::gltf_detail
