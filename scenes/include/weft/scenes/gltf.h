#pragma once
// glTF 2.0 (.gltf and .glb, told apart by the GLB magic) through tinygltf: meshes and fiber curves
// in world space (node hierarchy applied), cameras, KHR_lights_punctual lights and the emissive
// part of materials. docs/gltf.md lists what is supported and what is not.
// Fibers are LINE_STRIP primitives (mode 3) with POSITION (VEC3 float) and the custom attribute
// _RADIUS (SCALAR float, metres, one per point; weave.h writes them): the strips of one mesh
// instance form one FiberCurves (named like a mesh: node, ancestors, glTF mesh name; each strip's
// material key as for triangles). Their node transform must scale uniformly (it scales the radii
// too); a non-uniform one is an error naming the node. Other point and line primitives carry no
// area and are skipped with a warning. Images are not loaded (Weft binds its own materials).
// Accessors may be sparse. The node graph must be a set of trees (one parent per node, no
// cycles); it is walked without recursion, so any depth loads. Extensions in extensionsRequired
// that Weft cannot honour (mesh compression, quantization, ...) are errors naming them; ignored
// content (textured or extended materials, textures, morph targets, skins, animations) is one
// warning per kind. Everything malformed is a weft::Error naming the file and field.
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

// KHR_lights_punctual gives intensities in photometric units: lux (lm/m^2) for directional lights,
// candela (lm/sr) for point and spot lights. Weft's lights are radiometric (W/m^2, W/sr), so the
// loader divides by the luminous efficacy of monochromatic light at 555 nm, 683 lm/W (the SI
// definition of the candela). Blender's exporter multiplies by the same 683 (its "Standard"
// lighting mode), so a Blender sun of S W/m^2 loads as S W/m^2.
inline constexpr double kLuminousEfficacy_lm_per_W = 683.0;

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
  Lights lights;  // KHR_lights_punctual, converted to W/m^2 and W/sr
  std::vector<std::string> warnings;
  // What a render log should say about the file: each light with its glTF and converted values.
  std::vector<std::string> notes;
  // The files read: the glTF itself, then its external buffers (.bin) in buffer order. Images are
  // not read (textures do not shade), so they are not listed.
  std::vector<std::filesystem::path> files;
};

// How KHR_lights_punctual intensities are read: photometric (lux, candela; the specification's
// units, divided by kLuminousEfficacy_lm_per_W), or radiometric already (W/m^2, W/sr: exporters
// that write raw watts, e.g. Blender's "Unitless" lighting mode).
enum class GltfLightUnits { photometric, radiometric };

GltfContent load_gltf(const std::filesystem::path& path,
                      GltfLightUnits light_units = GltfLightUnits::photometric);

}  // namespace weft
