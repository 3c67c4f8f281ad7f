// glTF 2.0 loading: the file, its materials and its node trees (with their cameras); meshes and
// fibers: gltf_mesh.cpp, lights: gltf_lights.cpp. Debian's libtinygltf ships the implementation in
// a shared library, so these files only include the header. Every index and byte range that
// tinygltf hands over is checked before use: malformed files must end in a weft::Error, never in
// a crash.
#include "weft/scenes/gltf.h"

#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>

#include "gltf_internal.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

using namespace gltf_detail;

Affine local_transform(const Ctx& c, const tinygltf::Node& node, const std::string& field) {
  Affine a;
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16 || !finite_all(node.matrix))
      fail(c, field + ".matrix", "needs 16 finite numbers");
    // glTF matrices are column-major: element (row r, column k) is matrix[4 k + r].
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) a.m[r][k] = node.matrix[4 * k + r];
    a.t = {node.matrix[12], node.matrix[13], node.matrix[14]};
    return a;
  }
  Vec3 s{1, 1, 1};
  if (!node.scale.empty()) {
    if (node.scale.size() != 3 || !finite_all(node.scale))
      fail(c, field + ".scale", "needs 3 finite numbers");
    s = {node.scale[0], node.scale[1], node.scale[2]};
  }
  double qx = 0, qy = 0, qz = 0, qw = 1;
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4 || !finite_all(node.rotation))
      fail(c, field + ".rotation", "needs 4 finite numbers");
    qx = node.rotation[0], qy = node.rotation[1], qz = node.rotation[2], qw = node.rotation[3];
    const double len = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
    if (!(len > 0)) fail(c, field + ".rotation", "is the zero quaternion");
    qx /= len, qy /= len, qz /= len, qw /= len;
  }
  if (!node.translation.empty()) {
    if (node.translation.size() != 3 || !finite_all(node.translation))
      fail(c, field + ".translation", "needs 3 finite numbers");
    a.t = {node.translation[0], node.translation[1], node.translation[2]};
  }
  // Unit quaternion to rotation matrix, then M = T R S.
  const double r[3][3] = {
      {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
      {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
      {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a.m[i][j] = r[i][j] * s[j];
  return a;
}

void load_camera(const Ctx& c, const tinygltf::Node& node, const Affine& world,
                 const std::string& field) {
  if (node.camera < 0) return;
  if (static_cast<size_t>(node.camera) >= c.model.cameras.size())
    fail(c, field + ".camera", "camera index " + std::to_string(node.camera) + " out of range");
  const auto& gc = c.model.cameras[node.camera];
  const std::string cf = "cameras[" + std::to_string(node.camera) + "]";
  Camera cam;
  // glTF cameras look along local -z with +y up.
  const Vec3 f = world.vector({0, 0, -1}), u = world.vector({0, 1, 0});
  if (!(length(cross(f, u)) > 0) || !is_finite(f) || !is_finite(u))
    fail(c, field, "camera transform is singular or not finite");
  try {
    // The look-at point one unit ahead: f may be huge or tiny after scaling.
    cam = Camera::look_at(Camera::Type::perspective, world.point({0, 0, 0}),
                          world.point({0, 0, 0}) + normalize(f), u);
  } catch (const Error& e) {
    fail(c, field, std::string("camera: ") + e.what());
  }
  if (gc.type == "perspective") {
    if (!(gc.perspective.yfov > 0 && gc.perspective.yfov < kPi))
      fail(c, cf + ".perspective.yfov", "must lie in (0, pi)");
    cam.yfov_rad = gc.perspective.yfov;
  } else if (gc.type == "orthographic") {
    cam.type = Camera::Type::orthographic;
    // A scale in the node transform scales the film too.
    const double sx = length(world.vector({1, 0, 0})), sy = length(world.vector({0, 1, 0}));
    cam.half_width = std::abs(gc.orthographic.xmag) * sx;
    cam.half_height = std::abs(gc.orthographic.ymag) * sy;
    if (!(cam.half_width > 0 && cam.half_height > 0) ||
        !std::isfinite(cam.half_width * cam.half_height))
      fail(c, cf + ".orthographic", "xmag and ymag must be finite and non-zero");
  } else {
    fail(c, cf + ".type", "unknown camera type '" + gc.type + "'");
  }
  cam.validate(c.file, field);
  c.out->cameras.push_back({node.name.empty() ? gc.name : node.name, cam});
}
// The node graph checked before any traversal: child indices in range, at most one parent per node
// (glTF 2.0 section 3.5.3: the hierarchy is a set of disjoint trees), no cycles. Returns every
// node's parent (-1 for roots). Iterative throughout: a chain 10^4 nodes deep is legal glTF.
std::vector<int> node_parents(const Ctx& c) {
  const auto& nodes = c.model.nodes;
  std::vector<int> parent(nodes.size(), -1);
  for (size_t i = 0; i < nodes.size(); ++i)
    for (size_t k = 0; k < nodes[i].children.size(); ++k) {
      const int ch = nodes[i].children[k];
      const std::string field =
          "nodes[" + std::to_string(i) + "].children[" + std::to_string(k) + "]";
      if (ch < 0 || static_cast<size_t>(ch) >= nodes.size())
        fail(c, field,
             "node index " + std::to_string(ch) + " out of range (" + std::to_string(nodes.size()) +
                 " nodes)");
      if (parent[ch] >= 0 || static_cast<size_t>(ch) == i)
        fail(c, field,
             "nodes[" + std::to_string(ch) + "] has several parents (nodes[" +
                 std::to_string(static_cast<size_t>(ch) == i ? static_cast<int>(i) : parent[ch]) +
                 "] and nodes[" + std::to_string(i) +
                 "]): glTF node hierarchies must be trees; instance a mesh by giving it to several "
                 "nodes instead");
      parent[ch] = static_cast<int>(i);
    }
  // With one parent each, a cycle is a loop of parent links that never reaches a root.
  std::vector<uint8_t> state(nodes.size(),
                             0);  // 0 unknown, 1 on the current walk, 2 reaches a root
  for (size_t start = 0; start < nodes.size(); ++start) {
    int n = static_cast<int>(start);
    while (n >= 0 && state[n] == 0) state[n] = 1, n = parent[n];
    if (n >= 0 && state[n] == 1) {
      std::string loop = "nodes[" + std::to_string(n) + "]";
      for (int m = parent[n]; m != n; m = parent[m]) loop += " -> nodes[" + std::to_string(m) + "]";
      fail(c, "nodes[" + std::to_string(n) + "].children",
           "node hierarchy has a cycle (child to parent: " + loop + ")");
    }
    for (n = static_cast<int>(start); n >= 0 && state[n] == 1; n = parent[n]) state[n] = 2;
  }
  return parent;
}

// Names of a node's objects: its own name first, then its ancestors' (nearest first).
std::vector<std::string> node_names(const Ctx& c, const std::vector<int>& parent, int index) {
  std::vector<std::string> names;
  for (int n = index; n >= 0; n = parent[n])
    if (!c.model.nodes[n].name.empty()) names.push_back(c.model.nodes[n].name);
  return names;
}

void load_node(const Ctx& c, const std::vector<int>& parent, int index, const Affine& world) {
  const auto& m = c.model;
  const std::string field = "nodes[" + std::to_string(index) + "]";
  const auto& node = m.nodes[index];
  if (node.mesh >= 0) {
    if (static_cast<size_t>(node.mesh) >= m.meshes.size())
      fail(c, field + ".mesh", "mesh index " + std::to_string(node.mesh) + " out of range");
    const auto& mesh = m.meshes[node.mesh];
    auto mesh_names = node_names(c, parent, index);
    if (!mesh.name.empty()) mesh_names.push_back(mesh.name);
    FiberCurves curves;  // the instance's fibers: one FiberCurves, one object
    curves.names = mesh_names;
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
      load_primitive(
          c, mesh.primitives[p], world, mesh_names,
          "meshes[" + std::to_string(node.mesh) + "].primitives[" + std::to_string(p) + "]", field,
          curves);
    if (curves.curve_count() > 0)
      c.out->curves.push_back(std::make_shared<const FiberCurves>(std::move(curves)));
  }
  load_camera(c, node, world, field);
  load_light(c, node, world, field);
}

// Depth-first over the trees below 'roots', parents before children, children in order (the order
// meshes, cameras and lights come out in), with an explicit stack instead of recursion.
void load_nodes(const Ctx& c, const std::vector<int>& roots) {
  const auto& nodes = c.model.nodes;
  const std::vector<int> parent = node_parents(c);
  std::vector<uint8_t> seen(nodes.size(), 0);
  std::vector<std::pair<int, Affine>> stack;  // node and its parent's world transform
  for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.push_back({*r, Affine{}});
  while (!stack.empty()) {
    const auto [index, parent_world] = stack.back();
    stack.pop_back();
    const std::string field = "nodes[" + std::to_string(index) + "]";
    if (seen[index]) fail(c, field, "is reached twice from the scene's root nodes");
    seen[index] = 1;
    const Affine world = parent_world * local_transform(c, nodes[index], field);
    load_node(c, parent, index, world);
    const auto& ch = nodes[index].children;
    for (auto k = ch.rbegin(); k != ch.rend(); ++k) stack.push_back({*k, world});
  }
}

bool ignore_images(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                   const unsigned char*, int, void*) {
  return true;  // Weft binds its own materials; textures are not used.
}

// One warning per kind of content that Weft reads past, so that nobody expects it in the image.
void ignored_content_warnings(const Ctx& c) {
  const auto& m = c.model;
  auto warn = [&](const std::string& what) { c.out->warnings.push_back(c.file + ": " + what); };
  size_t shaded = 0;  // materials with more than a name, an emissive colour and doubleSided
  for (const auto& mat : m.materials) {
    const auto& pbr = mat.pbrMetallicRoughness;
    const bool plain_base = pbr.baseColorTexture.index < 0 &&
                            pbr.metallicRoughnessTexture.index < 0 && mat.normalTexture.index < 0 &&
                            mat.occlusionTexture.index < 0 && mat.emissiveTexture.index < 0;
    bool other_ext = false;
    for (const auto& [name, value] : mat.extensions)
      other_ext = other_ext || name != "KHR_materials_emissive_strength";
    if (!plain_base || other_ext) ++shaded;
  }
  if (shaded > 0)
    warn(std::to_string(shaded) +
         " glTF material(s) use textures or material extensions, which are ignored: Weft binds "
         "its own materials by glTF material name (the description's 'materials'); only the "
         "emissive colour and doubleSided are read");
  if (!m.textures.empty() || !m.images.empty())
    warn(std::to_string(m.textures.size()) + " texture(s) and " + std::to_string(m.images.size()) +
         " image(s) are ignored (images are not loaded)");
  size_t morphs = 0;
  for (const auto& mesh : m.meshes)
    for (const auto& prim : mesh.primitives) morphs += prim.targets.empty() ? 0 : 1;
  if (morphs > 0)
    warn(std::to_string(morphs) +
         " primitive(s) have morph targets, which are ignored: the base shape is rendered");
  size_t skinned = 0;
  for (const auto& node : m.nodes) skinned += node.skin >= 0 ? 1 : 0;
  if (!m.skins.empty() || skinned > 0)
    warn(std::to_string(m.skins.size()) +
         " skin(s) are ignored: skinned meshes are rendered unposed, under their node transform");
  if (!m.animations.empty())
    warn(std::to_string(m.animations.size()) +
         " animation(s) are ignored: nodes are rendered with the transforms written in the file");
}

// Extensions a file may require: those Weft reads, and those whose content Weft ignores anyway
// (material and texture extensions: Weft binds its own materials by name).
bool extension_usable(const std::string& name) {
  if (name == "KHR_lights_punctual" || name == "KHR_materials_emissive_strength") return true;
  return name.rfind("KHR_materials_", 0) == 0 || name == "KHR_texture_transform" ||
         name == "KHR_texture_basisu" || name == "EXT_texture_webp" || name == "MSFT_texture_dds";
}

// GLB (binary glTF) is recognised by its magic, whatever the file's extension; a version other
// than 2 is glTF 1.0's binary container, which tinygltf would misread.
bool is_glb(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[8] = {};
  if (!in.read(reinterpret_cast<char*>(head), 8)) return false;
  if (std::memcmp(head, "glTF", 4) != 0) return false;
  uint32_t version = 0;
  std::memcpy(&version, head + 4, 4);
  if (version != 2)
    throw Error(file, "GLB header version",
                "GLB version " + std::to_string(version) +
                    " is not supported: Weft reads glTF 2.0 (GLB version 2); re-export the "
                    "model as glTF 2.0");
  return true;
}

// tinygltf parses JSON recursively: bound the nesting before it sees the text (a deep 'extras'
// would overflow the stack). For GLB only the JSON chunk is JSON.
void check_gltf_json_depth(const std::string& file, bool binary) {
  std::ifstream in(file, std::ios::binary);
  std::string text;
  if (binary) {
    unsigned char head[20] = {};
    if (!in.read(reinterpret_cast<char*>(head), 20)) return;  // tinygltf reports the truncation
    uint32_t chunk_bytes = 0;
    std::memcpy(&chunk_bytes, head + 12, 4);
    const auto size = std::filesystem::file_size(file);
    if (std::memcmp(head + 16, "JSON", 4) != 0 || chunk_bytes > size - 20) return;
    text.resize(chunk_bytes);
    in.read(text.data(), static_cast<std::streamsize>(chunk_bytes));
  } else {
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  check_json_depth(text, file);
}

// The model of a .gltf or .glb file: glTF 2.0 whose required extensions Weft can honour;
// tinygltf's warnings go to 'warn'.
tinygltf::Model read_model(const std::filesystem::path& path, std::string& warn) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file, "", "glTF file not found");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_images, nullptr);
  tinygltf::Model model;
  std::string err;
  const bool binary = is_glb(file);
  check_gltf_json_depth(file, binary);
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                : loader.LoadASCIIFromFile(&model, &err, &warn, file);
  } catch (const std::bad_alloc&) {
    throw Error(file, "", "malformed glTF: a size or count in the file is too large to allocate");
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("malformed glTF: ") + e.what());
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    throw Error(file, "", "malformed glTF: " + (err.empty() ? std::string("unknown error") : err));
  }
  if (model.asset.version.rfind("2.", 0) != 0)
    throw Error(file, "asset.version",
                "'" + model.asset.version + "' is not supported: Weft reads glTF 2.0");
  std::string unsupported;
  for (const auto& e : model.extensionsRequired)
    if (!extension_usable(e)) unsupported += (unsupported.empty() ? "" : ", ") + e;
  if (!unsupported.empty())
    throw Error(file, "extensionsRequired",
                "unsupported extension(s) " + unsupported +
                    " (Weft reads KHR_lights_punctual and KHR_materials_emissive_strength and "
                    "ignores material and texture extensions); export without them, e.g. "
                    "without mesh compression");
  return model;
}

// The external buffers' files as tinygltf found them: relative to the glTF's folder,
// percent-escapes decoded.
std::vector<std::filesystem::path> buffer_files(const std::filesystem::path& path,
                                                const tinygltf::Model& model) {
  std::vector<std::filesystem::path> files;
  for (const auto& b : model.buffers)
    if (!b.uri.empty() && b.uri.rfind("data:", 0) != 0) {
      std::string uri;
      for (size_t k = 0; k < b.uri.size(); ++k) {
        if (b.uri[k] == '%' && k + 2 < b.uri.size() && std::isxdigit(uint8_t(b.uri[k + 1])) &&
            std::isxdigit(uint8_t(b.uri[k + 2]))) {
          uri += static_cast<char>(std::stoi(b.uri.substr(k + 1, 2), nullptr, 16));
          k += 2;
        } else {
          uri += b.uri[k];
        }
      }
      files.push_back(path.parent_path() / uri);
    }
  return files;
}

// What Weft reads of material 'i': its emission and doubleSided.
GltfMaterialInfo material_info(const Ctx& c, size_t i) {
  const auto& mat = c.model.materials[i];
  const std::string mf = "materials[" + std::to_string(i) + "]";
  GltfMaterialInfo info;
  info.double_sided = mat.doubleSided;
  if (mat.emissiveFactor.size() == 3) {
    if (!finite_all(mat.emissiveFactor)) fail(c, mf + ".emissiveFactor", "must be finite");
    info.emission = {mat.emissiveFactor[0], mat.emissiveFactor[1], mat.emissiveFactor[2]};
  }
  const auto ext = mat.extensions.find("KHR_materials_emissive_strength");
  if (ext != mat.extensions.end() && ext->second.IsObject() &&
      ext->second.Has("emissiveStrength")) {
    const auto& s = ext->second.Get("emissiveStrength");
    if (!s.IsNumber() || !std::isfinite(s.GetNumberAsDouble()) || s.GetNumberAsDouble() < 0)
      fail(c, mf + ".extensions.KHR_materials_emissive_strength.emissiveStrength", "must be >= 0");
    info.emission *= s.GetNumberAsDouble();
  }
  if (info.emission.r < 0 || info.emission.g < 0 || info.emission.b < 0)
    fail(c, mf + ".emissiveFactor", "must be >= 0");
  return info;
}

// The root nodes of the default scene (the first without one); with no scene, every node that is
// nobody's child.
std::vector<int> root_nodes(const Ctx& c) {
  const tinygltf::Model& model = c.model;
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int sc = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<size_t>(sc) >= model.scenes.size())
      fail(c, "scene", "scene index out of range");
    roots = model.scenes[sc].nodes;
    const std::string sf = "scenes[" + std::to_string(sc) + "].nodes";
    for (size_t k = 0; k < roots.size(); ++k)
      if (roots[k] < 0 || static_cast<size_t>(roots[k]) >= model.nodes.size())
        fail(c, sf + "[" + std::to_string(k) + "]",
             "node index " + std::to_string(roots[k]) + " out of range (" +
                 std::to_string(model.nodes.size()) + " nodes)");
  } else {
    std::vector<uint8_t> is_child(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
      for (int ch : n.children)
        if (ch >= 0 && static_cast<size_t>(ch) < model.nodes.size()) is_child[ch] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  return roots;
}

}  // namespace

GltfContent load_gltf(const std::filesystem::path& path, GltfLightUnits light_units) {
  const std::string file = path.string();
  std::string warn;
  const tinygltf::Model model = read_model(path, warn);
  GltfContent out;
  out.files.push_back(path);
  for (auto& f : buffer_files(path, model)) out.files.push_back(std::move(f));
  const Ctx c{model, file, &out, light_units};
  for (size_t i = 0; i < model.materials.size(); ++i) {
    const GltfMaterialInfo info = material_info(c, i);
    out.materials[material_key(c, static_cast<int>(i), "materials[" + std::to_string(i) + "]")] =
        info;
  }
  load_nodes(c, root_nodes(c));
  ignored_content_warnings(c);
  for (auto& w : warn)
    if (w == '\n') w = ' ';
  if (!warn.empty()) out.warnings.push_back(file + ": " + warn);
  return out;
}

}  // namespace weft
