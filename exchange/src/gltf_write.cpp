#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <sstream>

#include "gltf_asset.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/exchange/gltf_material.h"

namespace weft {
namespace gltf_detail {
namespace {

template <class T>
void append(std::vector<unsigned char>& out, const std::vector<T>& v) {
  const size_t at = out.size();
  out.resize(at + v.size() * sizeof(T));
  std::memcpy(out.data() + at, v.data(), v.size() * sizeof(T));
}

// One accessor over a fresh buffer view of 'bytes' bytes at 'offset' of buffer 0.
int add_accessor(tinygltf::Model& m, size_t offset, size_t bytes, int component, int type,
                 size_t count, int target) {
  tinygltf::BufferView bv;
  bv.buffer = 0;
  bv.byteOffset = offset;
  bv.byteLength = bytes;
  bv.target = target;
  m.bufferViews.push_back(bv);
  tinygltf::Accessor a;
  a.bufferView = static_cast<int>(m.bufferViews.size() - 1);
  a.componentType = component;
  a.type = type;
  a.count = count;
  m.accessors.push_back(a);
  return static_cast<int>(m.accessors.size() - 1);
}

// 'values' appended to the buffer, padded to 4 bytes so that the next view's floats align.
template <class T>
size_t append_aligned(std::vector<unsigned char>& out, const std::vector<T>& values) {
  const size_t at = out.size();
  append(out, values);
  out.resize((out.size() + 3) / 4 * 4, 0);
  return at;
}

// Mesh 'k' of the asset: its attributes and indices in buffer 0 (16-bit indices where they fit),
// one primitive with material 0, one node.
void add_mesh(tinygltf::Model& m, const GltfMesh& mesh) {
  auto& data = m.buffers[0].data;
  const size_t n = mesh.vertices();
  const int f = TINYGLTF_COMPONENT_TYPE_FLOAT, array = TINYGLTF_TARGET_ARRAY_BUFFER;
  const int p = add_accessor(m, append_aligned(data, mesh.positions_m), n * 12, f,
                             TINYGLTF_TYPE_VEC3, n, array);
  std::vector<double> lo(3, 1e30), hi(3, -1e30);
  for (size_t v = 0; v < n; ++v)
    for (size_t c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], static_cast<double>(mesh.positions_m[3 * v + c]));
      hi[c] = std::max(hi[c], static_cast<double>(mesh.positions_m[3 * v + c]));
    }
  m.accessors[static_cast<size_t>(p)].minValues = lo;
  m.accessors[static_cast<size_t>(p)].maxValues = hi;
  const int nr =
      add_accessor(m, append_aligned(data, mesh.normals), n * 12, f, TINYGLTF_TYPE_VEC3, n, array);
  const int t =
      add_accessor(m, append_aligned(data, mesh.uvs), n * 8, f, TINYGLTF_TYPE_VEC2, n, array);
  const size_t count = mesh.indices.size();
  int i = 0;
  if (n <= 0xffff) {
    const std::vector<uint16_t> short_indices(mesh.indices.begin(), mesh.indices.end());
    i = add_accessor(m, append_aligned(data, short_indices), count * 2,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, count,
                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  } else {
    i = add_accessor(m, append_aligned(data, mesh.indices), count * 4,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, count,
                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  tinygltf::Primitive prim;
  prim.attributes = {{"POSITION", p}, {"NORMAL", nr}, {"TEXCOORD_0", t}};
  prim.indices = i;
  prim.material = 0;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gm;
  gm.name = mesh.name;
  gm.primitives.push_back(prim);
  m.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = static_cast<int>(m.meshes.size() - 1);
  node.name = mesh.name;
  if (mesh.translation_m != std::array<double, 3>{0, 0, 0})
    node.translation = {mesh.translation_m[0], mesh.translation_m[1], mesh.translation_m[2]};
  m.nodes.push_back(node);
  m.scenes[0].nodes.push_back(static_cast<int>(m.nodes.size() - 1));
}

tinygltf::Value rgb_value(const Rgb& c) {
  return tinygltf::Value(
      tinygltf::Value::Array{tinygltf::Value(c.r), tinygltf::Value(c.g), tinygltf::Value(c.b)});
}

tinygltf::Material make_material(const GltfFit& fit, const std::string& name, double eps) {
  const GltfMaterial& g = fit.material;
  tinygltf::Material mat;
  mat.name = name;
  mat.doubleSided = true;
  mat.pbrMetallicRoughness.baseColorFactor = {g.base_color.r, g.base_color.g, g.base_color.b, 1};
  mat.pbrMetallicRoughness.metallicFactor = 0;
  mat.pbrMetallicRoughness.roughnessFactor = g.roughness;
  mat.extensions["KHR_materials_sheen"] = tinygltf::Value(
      tinygltf::Value::Object{{"sheenColorFactor", rgb_value(g.sheen_color)},
                              {"sheenRoughnessFactor", tinygltf::Value(g.sheen_roughness)}});
  if (g.transmission > 0)
    mat.extensions["KHR_materials_transmission"] = tinygltf::Value(
        tinygltf::Value::Object{{"transmissionFactor", tinygltf::Value(g.transmission)}});
  tinygltf::Value::Object extras{
      {"weft_fit_rms_log", tinygltf::Value(fit.rms_log)},
      {"weft_fit_points", tinygltf::Value(fit.points)},
      {"weft_fit_error",
       tinygltf::Value("RMS over view x light bin centres and RGB of log((f_gltf + eps) / "
                       "(f_table + eps)), eps = " +
                       std::to_string(eps) + " / sr")},
      {"weft_source", tinygltf::Value(name)}};
  if (g.diffuse_transmission > 0) {
    mat.extensions["KHR_materials_diffuse_transmission"] = tinygltf::Value(tinygltf::Value::Object{
        {"diffuseTransmissionFactor", tinygltf::Value(g.diffuse_transmission)},
        {"diffuseTransmissionColorFactor", rgb_value(g.diffuse_transmission_color)}});
    extras["weft_transmission_fit_rms_rel"] = tinygltf::Value(fit.transmission_rms_rel);
    extras["weft_transmission_fit_max_rel"] = tinygltf::Value(fit.transmission_max_rel);
    extras["weft_transmission_fit_error"] = tinygltf::Value(
        "relative error of the transmitted albedo (light from below reaching a view from above) "
        "against the table's, over the upper view bins and RGB: RMS and largest");
  }
  mat.extras = tinygltf::Value(std::move(extras));
  return mat;
}

}  // namespace

GltfMesh sample_quad() {
  GltfMesh q;
  q.name = "fabric_sample";
  q.positions_m = {-0.5f, 0, 0.5f, 0.5f, 0, 0.5f, 0.5f, 0, -0.5f, -0.5f, 0, -0.5f};
  q.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  q.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
  q.indices = {0, 1, 2, 0, 2, 3};
  return q;
}

std::string gltf_asset(const GltfFit& fit, const std::string& name, double epsilon_per_sr,
                       const std::vector<GltfMesh>& meshes, bool glb, const std::string& path) {
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = std::string("Weft ") + WEFT_VERSION + " (weft export)";
  m.extensionsUsed.push_back("KHR_materials_sheen");
  if (fit.material.transmission > 0) m.extensionsUsed.push_back("KHR_materials_transmission");
  if (fit.material.diffuse_transmission > 0)
    m.extensionsUsed.push_back("KHR_materials_diffuse_transmission");
  m.buffers.emplace_back();
  m.scenes.emplace_back();
  m.defaultScene = 0;
  for (const GltfMesh& mesh : meshes) add_mesh(m, mesh);
  m.materials.push_back(make_material(fit, name, epsilon_per_sr));
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&m, out, true, glb))
    throw Error(path, "", "tinygltf could not write the asset");
  return out.str();
}

ExportReport gltf_report(const GltfFit& fit) {
  ExportReport r{"glTF 2.0", {}, {}, {}};
  r.dropped = {"the table's angular detail beyond the fitted lobes (see the fit's error)",
               "anisotropy", "the back side (one material for both sides)"};
  const GltfMaterial& g = fit.material;
  if (g.diffuse_transmission > 0)
    r.notes.push_back(
        "transmission written as KHR_materials_diffuse_transmission (a Lambertian BTDF with its "
        "own colour, fitted to the table's transmitted albedo; viewers without the extension "
        "show the cloth opaque)");
  else if (g.transmission > 0)
    r.notes.push_back(
        "transmission written as KHR_materials_transmission: the table's transmission peaks "
        "straight through (" +
        std::to_string(fit.transmission_peak) +
        " times a diffuse one's), which glTF's rough specular BTDF follows; it is tinted by the "
        "base colour");
  else
    r.dropped.push_back("transmission (mean " + std::to_string(fit.transmittance) +
                        ", below the threshold)");
  r.figures = {{"fit RMS log error", fit.rms_log},
               {"fit RMS log error at start", fit.rms_log_start},
               {"direction pairs", fit.points},
               {"evaluations", fit.evaluations},
               {"base color R", fit.material.base_color.r},
               {"base color G", fit.material.base_color.g},
               {"base color B", fit.material.base_color.b},
               {"roughness", fit.material.roughness},
               {"sheen color R", fit.material.sheen_color.r},
               {"sheen color G", fit.material.sheen_color.g},
               {"sheen color B", fit.material.sheen_color.b},
               {"sheen roughness", fit.material.sheen_roughness},
               {"transmission", fit.material.transmission}};
  if (g.transmission > 0 || g.diffuse_transmission > 0)
    r.figures.push_back({"transmission straight-through peak", fit.transmission_peak});
  if (g.diffuse_transmission > 0) {
    r.figures.push_back({"diffuse transmission", g.diffuse_transmission});
    for (int c = 0; c < 3; ++c)
      r.figures.push_back(
          {std::string("diffuse transmission color ") + "RGB"[c], g.diffuse_transmission_color[c]});
    r.figures.push_back({"transmission fit RMS relative error", fit.transmission_rms_rel});
    r.figures.push_back({"transmission fit max relative error", fit.transmission_max_rel});
  }
  return r;
}

}  // namespace gltf_detail

ExportReport write_gltf_material(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                                 const std::string& name, const GltfFitOptions& options) {
  const std::string ext = path.extension().string();
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path.string(), "output", "a glTF file ends in .gltf or .glb");
  using namespace gltf_detail;
  const GltfFit fit = fit_gltf_material(table, options);
  write_text_atomically(path, gltf_asset(fit, name, options.epsilon_per_sr, {sample_quad()},
                                         ext == ".glb", path.string()));
  return gltf_report(fit);
}

}  // namespace weft
