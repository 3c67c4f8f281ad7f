// glTF output of the weave generator: triangle meshes (yarn tubes) and fiber curves (LINE_STRIP
// primitives with a _RADIUS attribute), one binary buffer, .gltf (base64) or .glb.
#include <algorithm>
#include <cstring>

#include "weave_internal.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"

namespace weft::detail {
namespace {

class Writer {
 public:
  size_t view(const void* data, size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t off = bin.size();
    bin.resize(off + bytes);
    if (bytes) std::memcpy(bin.data() + off, data, bytes);
    views.push_back(
        {{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes}, {"target", target}});
    return views.size() - 1;
  }
  // Float accessor over a whole new view.
  size_t floats(const std::vector<float>& v, int comps, const char* type, bool minmax) {
    return accessor(view(v.data(), v.size() * 4, 34962), 0, v.data(), v.size() / comps, comps, type,
                    minmax);
  }
  // Float accessor of 'count' elements at element 'first' of an existing view holding 'all'.
  size_t accessor(size_t view_index, size_t first, const float* all, size_t count, int comps,
                  const char* type, bool minmax) {
    nlohmann::json a = {{"bufferView", view_index},
                        {"byteOffset", first * comps * 4},
                        {"componentType", 5126},
                        {"count", count},
                        {"type", type}};
    if (first == 0) a.erase("byteOffset");
    if (minmax) {
      std::vector<double> lo(comps, 1e300), hi(comps, -1e300);
      for (size_t i = first * comps; i < (first + count) * comps; ++i) {
        lo[i % comps] = std::min(lo[i % comps], double(all[i]));
        hi[i % comps] = std::max(hi[i % comps], double(all[i]));
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  }
  size_t indices(const std::vector<uint32_t>& idx, size_t vertex_count) {
    size_t iv;
    int ctype;
    if (vertex_count <= 65535) {
      std::vector<uint16_t> small(idx.begin(), idx.end());
      iv = view(small.data(), small.size() * 2, 34963);
      ctype = 5123;
    } else {
      iv = view(idx.data(), idx.size() * 4, 34963);
      ctype = 5125;
    }
    accessors.push_back(
        {{"bufferView", iv}, {"componentType", ctype}, {"count", idx.size()}, {"type", "SCALAR"}});
    return accessors.size() - 1;
  }

  std::vector<uint8_t> bin;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
};

}  // namespace

GltfDocument build_gltf(const std::vector<TriangleMesh>* meshes, const FiberCurves* fibers,
                        const nlohmann::json& extras,
                        const std::vector<std::array<double, 3>>& yarn_rgb) {
  GltfDocument out;
  nlohmann::json& doc = out.doc;
  Writer w;
  doc["asset"] = {{"version", "2.0"}, {"generator", "weft weave"}};
  doc["extras"] = {{"weft_weave", extras}};
  doc["scene"] = 0;
  doc["scenes"] = nlohmann::json::array({{{"name", "patch"}, {"nodes", {0}}}});
  auto nodes = nlohmann::json::array({{{"name", "patch"}, {"children", nlohmann::json::array()}}});
  auto gmeshes = nlohmann::json::array(), materials = nlohmann::json::array();
  std::vector<std::string> material_names;
  auto material_index = [&](const std::string& name) {
    const auto it = std::find(material_names.begin(), material_names.end(), name);
    if (it != material_names.end()) return static_cast<size_t>(it - material_names.begin());
    material_names.push_back(name);
    // Base colours only help other viewers; Weft binds its own materials by these names.
    const double r = name == "warp" ? 0.6 : 0.5, g = name == "warp" ? 0.1 : 0.5;
    materials.push_back(
        {{"name", name}, {"pbrMetallicRoughness", {{"baseColorFactor", {r, g, g, 1.0}}}}});
    return material_names.size() - 1;
  };
  if (meshes) {
    for (const auto& m : *meshes) {
      nlohmann::json attrs = {{"POSITION", w.floats(m.positions, 3, "VEC3", true)},
                              {"NORMAL", w.floats(m.normals, 3, "VEC3", false)},
                              {"TANGENT", w.floats(m.tangents, 4, "VEC4", false)},
                              {"TEXCOORD_0", w.floats(m.uvs, 2, "VEC2", false)}};
      const size_t idx = w.indices(m.indices, m.vertex_count());
      const size_t mat = material_index(m.material);
      nodes[0]["children"].push_back(nodes.size());
      nodes.push_back({{"name", m.material}, {"mesh", gmeshes.size()}});
      gmeshes.push_back(
          {{"name", m.material + "_yarns"},
           {"primitives",
            {{{"attributes", attrs}, {"indices", idx}, {"material", mat}, {"mode", 4}}}}});
    }
  }
  if (fibers && fibers->curve_count() > 0) {
    const FiberCurves& f = *fibers;
    std::vector<float> pos(3 * f.point_count()), rad(f.point_count());
    for (size_t i = 0; i < f.point_count(); ++i) {
      for (int k = 0; k < 3; ++k) pos[3 * i + k] = f.points[4 * i + k];
      rad[i] = f.points[4 * i + 3];
    }
    // One view each for all positions and all radii; accessors sharing a vertex view need its
    // byteStride (glTF 2.0, 3.6.2.4).
    const size_t pv = w.view(pos.data(), pos.size() * 4, 34962);
    const size_t rv = w.view(rad.data(), rad.size() * 4, 34962);
    w.views[pv]["byteStride"] = 12;
    w.views[rv]["byteStride"] = 4;
    // Curves of one yarn are consecutive; one node and mesh per yarn.
    std::vector<nlohmann::json> yarn_prims(f.yarn_material.size(), nlohmann::json::array());
    for (size_t c = 0; c < f.curve_count(); ++c) {
      const size_t first = f.curve_first[c], n = f.curve_points[c];
      yarn_prims[f.curve_yarn[c]].push_back(
          {{"attributes",
            {{"POSITION", w.accessor(pv, first, pos.data(), n, 3, "VEC3", true)},
             {"_RADIUS", w.accessor(rv, first, rad.data(), n, 1, "SCALAR", false)}}},
           {"material", material_index(f.material(c))},
           {"mode", 3}});
    }
    std::vector<int> per_material(2, 0);
    for (size_t y = 0; y < f.yarn_material.size(); ++y) {
      const std::string& mat = f.yarn_material[y];
      const std::string name = mat + "_" + std::to_string(per_material[mat == "warp" ? 0 : 1]++);
      nlohmann::json node = {{"name", name}, {"mesh", gmeshes.size()}};
      if (y < yarn_rgb.size()) node["extras"] = {{"color_rgb", yarn_rgb[y]}};
      nodes[0]["children"].push_back(nodes.size());
      nodes.push_back(node);
      gmeshes.push_back({{"name", name}, {"primitives", yarn_prims[y]}});
    }
  }
  while (w.bin.size() % 4) w.bin.push_back(0);
  doc["nodes"] = nodes;
  doc["materials"] = materials;
  doc["meshes"] = gmeshes;
  doc["accessors"] = w.accessors;
  doc["bufferViews"] = w.views;
  doc["buffers"] = nlohmann::json::array({{{"byteLength", w.bin.size()}}});
  out.bin = std::move(w.bin);
  return out;
}

std::string gltf_text(GltfDocument d) {
  d.doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(d.bin);
  return d.doc.dump(1) + "\n";
}

std::vector<uint8_t> glb_bytes(const GltfDocument& d) {
  std::string json = d.doc.dump();
  while (json.size() % 4) json += ' ';
  std::vector<uint8_t> out;
  out.reserve(28 + json.size() + d.bin.size());
  auto u32 = [&](uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<uint8_t>(v >> (8 * k)));
  };
  u32(0x46546C67);  // "glTF"
  u32(2);
  u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + d.bin.size()));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);  // "JSON"
  out.insert(out.end(), json.begin(), json.end());
  u32(static_cast<uint32_t>(d.bin.size()));
  u32(0x004E4942);  // "BIN\0"
  out.insert(out.end(), d.bin.begin(), d.bin.end());
  return out;
}

void write_gltf(const std::filesystem::path& path, const GltfDocument& d) {
  const auto ext = path.extension().string();
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path.string(), "", "output must end in .gltf or .glb");
  if (ext == ".gltf") {
    write_text_atomically(path, gltf_text(d));
    return;
  }
  if (12 + 8 + d.doc.dump().size() + 8 + d.bin.size() + 8 > 0xFFFFFFFFull)
    throw Error(path.string(), "", "a .glb holds at most 4 GiB; write .gltf or fewer repeats");
  const auto bytes = glb_bytes(d);
  write_bytes_atomically(path, bytes);
}

}  // namespace weft::detail
