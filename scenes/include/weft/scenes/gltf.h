#pragma once
// glTF 2.0 (.gltf and .glb) through tinygltf: meshes and fiber curves in world space (node
// hierarchy applied), cameras, KHR_lights_punctual lights and the emissive part of materials.
// Fibers are LINE_STRIP primitives (mode 3) with POSITION (VEC3 float) and the custom attribute
// _RADIUS (SCALAR float, metres, one per point; weave.h writes them): the strips of one mesh
// instance form one FiberCurves (named like a mesh: node, ancestors, glTF mesh name; each strip's
// material key as for triangles). Their node transform must scale uniformly (it scales the radii
// too); a non-uniform one is an error naming the node. Other point and line primitives carry no
// area and are skipped with a warning. Images are not loaded (Weft binds its own materials).
// Everything malformed is a weft::Error naming the file and field.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/lights.h"
#include "weft/scenes/mesh.h"

namespace weft {

struct GltfMaterialInfo {
  Rgb emission{0.0};          // emissiveFactor x KHR_materials_emissive_strength
  bool double_sided = false;  // glTF doubleSided: emission leaves both faces
};

struct NamedCamera {
  std::string name;  // node name, else camera name
  Camera camera;
};

struct GltfContent {
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;  // tangents always present
  std::vector<std::shared_ptr<const FiberCurves>> curves;   // one per mesh instance with fibers
  std::map<std::string, GltfMaterialInfo> materials;        // by binding key
  std::vector<NamedCamera> cameras;
  Lights lights;  // KHR_lights_punctual; glTF units (lux, candela) read as W/m^2 and W/sr
  std::vector<std::string> warnings;
};

GltfContent load_gltf(const std::filesystem::path& path);

}  // namespace weft
