#pragma once
// The scene description file (JSON): glTF files (relative paths), bindings of glTF material names
// to Weft materials, lights, camera, render settings and an optional gonioreflectometer sweep.
// Parsing only: the result is plain data; render_scene.h turns it into something renderable.
// The "render" and "sweep" sections are kept as written: the integrators own those settings and
// read them (render_settings.h documents "render", gonio.h "sweep").
//
// {
//   "gltf": "plane.gltf" | ["a.gltf", "b.glb"],
//   "gltf_light_units": "photometric" | "radiometric",  // KHR_lights_punctual values (gltf.h)
//   "objects": [ inline primitives, for tests:
//     {"type": "quad", "name": N, "material": KEY, "center": [3], "normal": [3], "tangent": [3],
//      "size": [w, h]} |
//     {"type": "sphere", "name": N, "material": KEY, "center": [3], "radius": r,
//      "subdivisions": k, "inward": false, "smooth": true} |
//     {"type": "fiber", "name": N, "material": KEY, "from": [3], "to": [3], "radius": r,
//      "segments": 1} ],                                  // a straight fiber (metres)
//   "fiber_geometry": {"type": "curves"} | {"type": "tubes", "sides": 8},  // curves.h
//   "materials": { KEY: {"type": T, "params": {...}, "emission": c, "double_sided": b} },
//   "default_material": {"type": T, "params": {...}},      // for keys with no binding
//   "frame": {"normal": [0,1,0], "tangent": [1,0,0]},      // zenith/azimuth reference (glTF Y up)
//   "lights": [ {"type": "parallel", "irradiance": c, "zenith_deg": t, "azimuth_deg": p} |
//               {"type": "parallel", "irradiance": c, "direction": [3]}  (towards the light) |
//               {"type": "environment", "radiance": c} |
//               {"type": "environment", "file": "sky.exr", "scale": c} |  (environment_map.h)
//               {"type": "sky", "zenith_radiance": c, "sun_zenith_deg": t, "sun_azimuth_deg": p,
//                "resolution": [256, 128]} |               (CIE clear sky, environment_map.h)
//               {"type": "point", "position": [3], "intensity": c} |
//               {"type": "spot", "position": [3], "direction": [3], "intensity": c,
//                "inner_cone_deg": a, "outer_cone_deg": b} ],
//   "camera": {"gltf_camera": NAME} |
//             {"type": "perspective", "position": [3], "look_at": [3], "up": [3], "yfov_deg": f} |
//             {"type": "orthographic", "position": [3], "look_at": [3], "up": [3],
//              "half_width": w, "half_height": h} |
//             {"type": "orthographic", "frame_object": NAME, "zenith_deg": t, "azimuth_deg": p},
//   "render": {...},                                       // weft/integrators/render_settings.h
//   "sweep": {...}                                         // weft/integrators/gonio.h
// }
// Shapes: the meshes (glTF triangles, inline quads and spheres) followed by the fiber curve sets
// (glTF LINE_STRIP + _RADIUS, inline fibers); a shape index is a mesh index or meshes.size() plus a
// curve set's index. Objects select shapes by name, materials bind meshes and fibers alike.
// A colour c is a number or [r, g, b]. Unknown keys, wrong types, out-of-range values and missing
// files are weft::Error naming the file and the field.
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/spectrum.h"
#include "weft/scenes/camera.h"
#include "weft/scenes/curves.h"
#include "weft/scenes/gltf.h"
#include "weft/scenes/lights.h"
#include "weft/scenes/mesh.h"

namespace weft {

struct MaterialBinding {
  std::string type;  // a name make_bsdf knows
  nlohmann::json params = nlohmann::json::object();
  std::optional<Rgb> emission;  // overrides the glTF emissive colour when set
  std::optional<bool> double_sided;
  std::string field;  // where it was declared, for error messages
};

// The reference frame of zenith/azimuth angles: zenith from 'normal', azimuth from 'tangent'
// towards normal x tangent.
struct AngleFrame {
  Vec3 normal{0, 1, 0};
  Vec3 tangent{1, 0, 0};
  Vec3 direction(double zenith_rad, double azimuth_rad) const;
};

// Upper bound on colours a description gives: generous, but it rejects typos like 1e300.
inline constexpr double kMaxDescriptionRadiometric = 1e12;

struct SceneDescription {
  std::string source;  // the description file, for error messages
  std::filesystem::path base_dir = ".";
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  std::vector<std::shared_ptr<const FiberCurves>> curves;  // shapes meshes.size() + k
  // Placements of the meshes, each a shift (metres, float values): empty, every mesh once where it
  // is; else RenderScene traces every mesh at each shift, one stored copy and one acceleration
  // structure reached through Embree instances (a periodic sample's neighbours without their
  // memory). A hit's shape is then the mesh's index whatever the placement. Curves are never
  // shifted; emissive meshes cannot be (the area light samples the stored triangles).
  std::vector<Vec3> mesh_shifts;
  FiberGeometry fiber_geometry;                            // how RenderScene builds the curves
  std::map<std::string, GltfMaterialInfo> gltf_materials;  // emissive info by binding key
  std::map<std::string, MaterialBinding> materials;        // bindings by key
  std::optional<MaterialBinding> default_material;
  Lights lights;
  std::optional<Camera> camera;
  // Every glTF camera, file by file in the order of "gltf", each file's in its node order
  // (unnamed ones have an empty name): what --camera selects from (select_camera).
  std::vector<NamedCamera> gltf_cameras;
  AngleFrame frame;
  // The "render" and "sweep" sections as written (absent: nullopt), read by the integrators with
  // errors naming 'source' and the section.
  std::optional<nlohmann::json> render, sweep;
  std::vector<std::string> warnings;
  std::vector<std::string> notes;  // for the render log (gltf.h: how glTF lights were converted)
  // Every file the description read besides itself: glTF files and their buffers
  // (GltfContent::files), environment maps. Material tables are read later (registry.h).
  std::vector<std::filesystem::path> files;

  size_t shape_count() const { return meshes.size() + curves.size(); }
  // Bounding box of the shapes selected by 'object' (every shape when empty); Error when none.
  Bounds3 object_bounds(const std::string& object) const;
  // Per-shape flags of the shapes selected by 'object'; Error listing known names when none.
  std::vector<uint8_t> select_object(const std::string& object) const;
  // The binding for a material key of a mesh or fiber (default_material where unbound); Error when
  // neither.
  const MaterialBinding& binding_for(const std::string& key) const;
};

// A "-D key=value" override of a value in a description (docs/scenes.md, "Overrides"). The key is
// the value's JSON path as errors print it: names joined by '.', array elements as [i] (or .i),
// e.g. "materials.seat.params.reflectance", "lights[0].irradiance", "render.spp". A name may
// itself hold dots (glTF material names such as "Material.001"): the longest name that exists
// is taken.
struct SceneOverride {
  std::string key, value;
};
// "key=value" split at the first '='; Error naming the option when there is no '=' or no key.
SceneOverride parse_scene_override(const std::string& text);
// Sets each value in the description's JSON 'j', in order. Everything up to the last name must
// exist (a top-level section such as "render" is made when absent); the last name may be new in
// an existing object, and the parser then checks it as if it were written in the file. The value
// is JSON (0.5, [1, 0, 0], true, "text") or else text; an existing string takes the text as
// written. Replacing a value by one of another kind (a number by text, an object by a number) is
// an error; a number and a list of numbers stand for each other (colours). Errors name 'source'
// and "-D KEY".
void apply_scene_overrides(nlohmann::json& j, const std::vector<SceneOverride>& overrides,
                           const std::string& source);

SceneDescription load_scene_description(const std::filesystem::path& path,
                                        const std::vector<SceneOverride>& overrides = {});

// The camera a user picks with --camera: a glTF camera by name (node name, else camera name) or by
// index in SceneDescription::gltf_cameras ("0", "1", ...; a name of digits only is taken as an
// index). Error naming 'source' and --camera that lists the cameras there are.
NamedCamera select_camera(const SceneDescription& desc, const std::string& which);
// Same from parsed JSON; relative paths resolve against base_dir, errors name 'source'.
SceneDescription parse_scene_description(const nlohmann::json& j,
                                         const std::filesystem::path& base_dir,
                                         const std::string& source);

// Every file a render or sweep of the description at 'scene' reads: the description, its glTF
// files and buffers and environment maps, and what its materials name (tables, a fabric table's
// weave table, measured networks,
// fiber specs; a preset name is no file). Relative names resolve as the registry and the bake
// cache resolve them.
std::vector<std::filesystem::path> scene_input_files(const std::string& scene,
                                                     const SceneDescription& d);
// The same named for the output guard, with the scene's fiber-table bake cache folder.
std::vector<NamedPath> scene_inputs(const std::string& scene, const SceneDescription& d);

}  // namespace weft
