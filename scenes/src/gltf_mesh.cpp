// glTF accessors (sparse ones included), triangle meshes and fiber curves. Every index and byte
// range that tinygltf hands over is checked here before use.
#include <algorithm>
#include <cstring>
#include <memory>

#include "gltf_internal.h"

namespace weft::gltf_detail {
namespace {

// Where the bytes of accessor 'index' are, after checking every index and range. A sparse
// accessor (glTF 2.0 section 3.6.2.3) is materialised into 'owned': its base elements (zeros
// without a bufferView), then the substituted ones.
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t count = 0, stride = 0;
  int component_type = 0, components = 0;
  bool normalized = false;
  std::shared_ptr<std::vector<unsigned char>> owned;
};

// A sparse accessor without a bufferView holds no bytes in the file, so nothing bounds its count
// but this: 2^24 elements (a 16.7-million-vertex attribute, 400 MB as VEC3 doubles).
constexpr size_t kMaxZeroInitialisedElements = size_t(1) << 24;

// Checks that 'count' elements of 'elem' bytes at 'stride' from byte 'offset' of bufferView
// 'view_index' lie inside it and its buffer; returns their first byte.
const unsigned char* view_bytes(const Ctx& c, int view_index, size_t offset, size_t count,
                                size_t stride, size_t elem, const std::string& field) {
  const auto& m = c.model;
  if (view_index < 0 || static_cast<size_t>(view_index) >= m.bufferViews.size())
    fail(c, field + ".bufferView", "index " + std::to_string(view_index) + " out of range");
  const auto& view = m.bufferViews[view_index];
  const std::string vf = "bufferViews[" + std::to_string(view_index) + "]";
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m.buffers.size())
    fail(c, vf + ".buffer", "index " + std::to_string(view.buffer) + " out of range");
  const auto& buffer = m.buffers[view.buffer];
  if (view.byteOffset > buffer.data.size() ||
      view.byteLength > buffer.data.size() - view.byteOffset)
    fail(c, vf,
         "byte range exceeds buffer " + std::to_string(view.buffer) + " (" +
             std::to_string(buffer.data.size()) + " bytes)");
  if (offset > view.byteLength) fail(c, field + ".byteOffset", "exceeds its bufferView");
  // Compared by division, not by multiplying: the count is the file's and may be absurd.
  const size_t avail = view.byteLength - offset;
  if (count > 0 && (elem > avail || (count - 1) > (avail - elem) / stride))
    fail(c, field,
         "count " + std::to_string(count) + ": byte range exceeds its bufferView (" + vf + ", " +
             std::to_string(view.byteLength) + " bytes)");
  return buffer.data.data() + view.byteOffset + offset;
}

AccessorView accessor_view(const Ctx& c, int index, const std::string& field) {
  const auto& m = c.model;
  if (index < 0 || static_cast<size_t>(index) >= m.accessors.size())
    fail(c, field,
         "accessor index " + std::to_string(index) + " out of range (" +
             std::to_string(m.accessors.size()) + " accessors)");
  const auto& acc = m.accessors[index];
  const std::string af = "accessors[" + std::to_string(index) + "]";
  const int csize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(acc.componentType));
  const int ncomp = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(acc.type));
  if (csize <= 0 || ncomp <= 0) fail(c, af, "unknown componentType or type");
  const size_t elem = static_cast<size_t>(csize) * ncomp;
  AccessorView out{nullptr, acc.count, elem, acc.componentType, ncomp, acc.normalized, nullptr};
  if (acc.bufferView >= 0 || !acc.sparse.isSparse) {
    if (acc.bufferView < 0 || static_cast<size_t>(acc.bufferView) >= m.bufferViews.size())
      fail(c, af + ".bufferView", "index " + std::to_string(acc.bufferView) + " out of range");
    const auto& view = m.bufferViews[acc.bufferView];
    const int stride = acc.ByteStride(view);
    const std::string vf = "bufferViews[" + std::to_string(acc.bufferView) + "]";
    if (stride <= 0) fail(c, vf + ".byteStride", "invalid");
    if (static_cast<size_t>(stride) < elem) fail(c, vf + ".byteStride", "smaller than an element");
    out.stride = static_cast<size_t>(stride);
    out.data = view_bytes(c, acc.bufferView, acc.byteOffset, acc.count, out.stride, elem, af);
  } else if (acc.count > kMaxZeroInitialisedElements) {
    fail(c, af + ".count",
         std::to_string(acc.count) + " elements without a bufferView (at most " +
             std::to_string(kMaxZeroInitialisedElements) + ")");
  }
  if (!acc.sparse.isSparse) return out;

  // Sparse: copy the base elements tightly packed, then overwrite the listed ones. Every size is
  // checked against the buffers above and below before anything is allocated.
  const std::string sf = af + ".sparse";
  const auto& sp = acc.sparse;
  if (sp.count < 1 || static_cast<size_t>(sp.count) > acc.count)
    fail(c, sf + ".count",
         "must lie in [1, accessor count " + std::to_string(acc.count) + "], got " +
             std::to_string(sp.count));
  const int isize =
      tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(sp.indices.componentType));
  if (sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    fail(c, sf + ".indices.componentType", "must be unsigned byte, short or int");
  if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) fail(c, sf, "byteOffset must be >= 0");
  const size_t n = static_cast<size_t>(sp.count);
  const unsigned char* ip =
      view_bytes(c, sp.indices.bufferView, sp.indices.byteOffset, n, isize, isize, sf + ".indices");
  const unsigned char* vp =
      view_bytes(c, sp.values.bufferView, sp.values.byteOffset, n, elem, elem, sf + ".values");
  auto owned = std::make_shared<std::vector<unsigned char>>(acc.count * elem, 0);
  if (out.data)
    for (size_t i = 0; i < acc.count; ++i)
      std::memcpy(owned->data() + i * elem, out.data + i * out.stride, elem);
  uint64_t previous = 0;
  for (size_t k = 0; k < n; ++k) {
    uint64_t target = 0;
    if (isize == 1) {
      target = ip[k];
    } else if (isize == 2) {
      uint16_t v;
      std::memcpy(&v, ip + 2 * k, 2);
      target = v;
    } else {
      uint32_t v;
      std::memcpy(&v, ip + 4 * k, 4);
      target = v;
    }
    // The specification requires strictly increasing indices.
    if (target >= acc.count || (k > 0 && target <= previous))
      fail(c, sf + ".indices",
           "index " + std::to_string(target) + " at " + std::to_string(k) +
               " is out of range or not strictly increasing");
    previous = target;
    std::memcpy(owned->data() + target * elem, vp + k * elem, elem);
  }
  out.data = owned->data();
  out.stride = elem;
  out.owned = std::move(owned);
  return out;
}

double read_component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    default:
      return 0;
  }
}

// Reads a float attribute with 'components' components (float, or normalized integers when
// 'allow_normalized'); non-finite values are errors.
std::vector<double> read_attribute(const Ctx& c, int index, int components, bool allow_normalized,
                                   const std::string& field) {
  const AccessorView v = accessor_view(c, index, field);
  if (v.components != components)
    fail(c, field, "expected " + std::to_string(components) + " components per element");
  const bool ok_type = v.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                       (allow_normalized && v.normalized &&
                        v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  if (!ok_type) fail(c, field, "unsupported component type " + std::to_string(v.component_type));
  const int csize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(v.component_type));
  std::vector<double> out(v.count * components);
  for (size_t i = 0; i < v.count; ++i)
    for (int k = 0; k < components; ++k) {
      const double x =
          read_component(v.data + i * v.stride + k * csize, v.component_type, v.normalized);
      if (!std::isfinite(x)) fail(c, field, "non-finite value at element " + std::to_string(i));
      out[i * components + k] = x;
    }
  return out;
}

std::vector<uint32_t> read_indices(const Ctx& c, int index, const std::string& field) {
  const AccessorView v = accessor_view(c, index, field);
  if (v.components != 1) fail(c, field, "indices must be SCALAR");
  std::vector<uint32_t> out(v.count);
  for (size_t i = 0; i < v.count; ++i) {
    const unsigned char* p = v.data + i * v.stride;
    switch (v.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        out[i] = p[0];
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        std::memcpy(&s, p, 2);
        out[i] = s;
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        std::memcpy(&out[i], p, 4);
        break;
      default:
        fail(c, field, "indices must be unsigned byte, short or int");
    }
  }
  return out;
}

// The accessor of a primitive's attribute 'name'; kNoAttribute when it has none.
constexpr int kNoAttribute = -2;
int attribute_accessor(const tinygltf::Primitive& prim, const char* name) {
  const auto it = prim.attributes.find(name);
  return it == prim.attributes.end() ? kNoAttribute : it->second;
}

// Every vertex index must be below the vertex count nv.
void check_indices(const Ctx& c, const std::vector<uint32_t>& idx, size_t nv,
                   const std::string& field) {
  for (size_t i = 0; i < idx.size(); ++i)
    if (idx[i] >= nv)
      fail(c, field,
           "index " + std::to_string(idx[i]) + " at " + std::to_string(i) +
               " exceeds the vertex count " + std::to_string(nv));
}

// The uniform scale of a transform's linear part; Error naming the node when it scales unevenly
// (a round fiber would turn elliptic) or is singular.
double uniform_scale(const Ctx& c, const Affine& world, const std::string& node_field) {
  Vec3 col[3];
  for (int k = 0; k < 3; ++k) col[k] = {world.m[0][k], world.m[1][k], world.m[2][k]};
  const double l0 = length(col[0]), l1 = length(col[1]), l2 = length(col[2]);
  const double s = (l0 + l1 + l2) / 3;
  const double tol = 1e-6 * s;
  if (!(s > 0) || !std::isfinite(s))
    fail(c, node_field, "node transform of fiber curves is singular");
  if (std::abs(l0 - s) > tol || std::abs(l1 - s) > tol || std::abs(l2 - s) > tol ||
      std::abs(dot(col[0], col[1])) > tol * s || std::abs(dot(col[0], col[2])) > tol * s ||
      std::abs(dot(col[1], col[2])) > tol * s)
    fail(c, node_field,
         "fiber curves (LINE_STRIP with _RADIUS) need a uniform scale: a non-uniform one would "
         "make the round fibers elliptic");
  return s;
}

// Curve point totals are stored in 32 bits and handed to Embree as its vertex count.
constexpr size_t kMaxCurvePoints = size_t(1) << 31;

// A LINE_STRIP with _RADIUS: one fiber, appended to 'curves' (the mesh instance's fibers).
void load_curve(const Ctx& c, const tinygltf::Primitive& prim, const Affine& world,
                const std::string& field, const std::string& node_field, FiberCurves& curves) {
  auto attr = [&](const char* name) { return attribute_accessor(prim, name); };
  const std::string af = field + ".attributes.";
  if (attr("POSITION") == kNoAttribute) fail(c, af + "POSITION", "is required");
  const double scale = uniform_scale(c, world, node_field);
  // Sizes first: nothing is allocated for counts the buffers cannot hold or Embree cannot index.
  const AccessorView pv = accessor_view(c, attr("POSITION"), af + "POSITION");
  const AccessorView rv = accessor_view(c, attr("_RADIUS"), af + "_RADIUS");
  if (rv.count != pv.count)
    fail(c, af + "_RADIUS",
         "count " + std::to_string(rv.count) + " differs from POSITION's " +
             std::to_string(pv.count));
  if (rv.components != 1) fail(c, af + "_RADIUS", "must be SCALAR (one radius per point)");
  if (rv.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
    fail(c, af + "_RADIUS", "must be float (metres)");
  size_t strip = pv.count;
  if (prim.indices >= 0) strip = accessor_view(c, prim.indices, field + ".indices").count;
  if (strip < 2) fail(c, field, "a fiber (LINE_STRIP) needs at least 2 points");
  if (strip > kMaxCurvePoints - curves.point_count())
    fail(c, field, "too many fiber points (at most 2^31 per mesh)");
  const auto pos = read_attribute(c, attr("POSITION"), 3, false, af + "POSITION");
  const auto rad = read_attribute(c, attr("_RADIUS"), 1, false, af + "_RADIUS");
  const size_t nv = rad.size();
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    idx = read_indices(c, prim.indices, field + ".indices");
    check_indices(c, idx, nv, field + ".indices");
  }
  const std::string key = material_key(c, prim.material, field + ".material");
  auto yarn = std::find(curves.yarn_material.begin(), curves.yarn_material.end(), key);
  if (yarn == curves.yarn_material.end())
    yarn = curves.yarn_material.insert(curves.yarn_material.end(), key);
  curves.curve_first.push_back(static_cast<uint32_t>(curves.point_count()));
  curves.curve_points.push_back(static_cast<uint32_t>(strip));
  curves.curve_yarn.push_back(static_cast<uint32_t>(yarn - curves.yarn_material.begin()));
  curves.points.reserve(curves.points.size() + 4 * strip);
  for (size_t k = 0; k < strip; ++k) {
    const size_t v = idx.empty() ? k : idx[k];
    if (!(rad[v] > 0))
      fail(c, af + "_RADIUS", "radius at element " + std::to_string(v) + " must be > 0");
    const Vec3 p = world.point({pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]});
    const double r = rad[v] * scale;
    if (!in_traceable_range(p)) fail(c, af + "POSITION", "position out of range after transform");
    if (!(r > 0 && r < kMaxCameraCoordinate_m))
      fail(c, af + "_RADIUS",
           "radius out of range after transform at element " + std::to_string(v));
    curves.points.insert(curves.points.end(),
                         {float(p.x), float(p.y), float(p.z), static_cast<float>(r)});
  }
}

// A triangle primitive's vertex attributes as the file has them, each of POSITION's count
// (normals, tangents and texture coordinates empty when absent).
struct VertexAttributes {
  std::vector<double> pos, nrm, tan, uv;  // 3, 3, 4 and 2 values a vertex
};
VertexAttributes read_vertex_attributes(const Ctx& c, const tinygltf::Primitive& prim,
                                        const std::string& af) {
  auto attr = [&](const char* name) { return attribute_accessor(prim, name); };
  if (attr("POSITION") == kNoAttribute) fail(c, af + "POSITION", "is required");
  VertexAttributes a;
  a.pos = read_attribute(c, attr("POSITION"), 3, false, af + "POSITION");
  const size_t nv = a.pos.size() / 3;
  if (attr("NORMAL") != kNoAttribute)
    a.nrm = read_attribute(c, attr("NORMAL"), 3, false, af + "NORMAL");
  if (attr("TANGENT") != kNoAttribute)
    a.tan = read_attribute(c, attr("TANGENT"), 4, false, af + "TANGENT");
  if (attr("TEXCOORD_0") != kNoAttribute)
    a.uv = read_attribute(c, attr("TEXCOORD_0"), 2, true, af + "TEXCOORD_0");
  if (!a.nrm.empty() && a.nrm.size() != 3 * nv)
    fail(c, af + "NORMAL", "count differs from POSITION");
  if (!a.tan.empty() && a.tan.size() != 4 * nv)
    fail(c, af + "TANGENT", "count differs from POSITION");
  if (!a.uv.empty() && a.uv.size() != 2 * nv)
    fail(c, af + "TEXCOORD_0", "count differs from POSITION");
  return a;
}

// The triangles' vertex indices, three a triangle, from a list, strip or fan of nv vertices.
std::vector<uint32_t> triangle_indices(const Ctx& c, const tinygltf::Primitive& prim, size_t nv,
                                       const std::string& field) {
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    idx = read_indices(c, prim.indices, field + ".indices");
  } else {
    idx.resize(nv);
    for (size_t i = 0; i < nv; ++i) idx[i] = static_cast<uint32_t>(i);
  }
  check_indices(c, idx, nv, field + ".indices");
  std::vector<uint32_t> tri;
  if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 2; i < idx.size(); ++i) {
      if (i % 2 == 0)
        tri.insert(tri.end(), {idx[i - 2], idx[i - 1], idx[i]});
      else
        tri.insert(tri.end(), {idx[i - 1], idx[i - 2], idx[i]});
    }
  } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 2; i < idx.size(); ++i) tri.insert(tri.end(), {idx[0], idx[i - 1], idx[i]});
  } else {
    if (idx.size() % 3 != 0) fail(c, field + ".indices", "count is not a multiple of 3");
    tri = std::move(idx);
  }
  return tri;
}

// The vertices through the node transform 'world' (of determinant 'det') into the mesh's float
// arrays: positions, unit normals and tangents (handedness flipped by a mirroring transform).
void transform_vertices(const Ctx& c, const VertexAttributes& a, const Affine& world, double det,
                        const std::string& af, TriangleMesh& mesh) {
  const size_t nv = a.pos.size() / 3;
  const Affine nm = world.normal_matrix();
  // Vertex v of a packed attribute ('stride' values per vertex) and of the mesh's float arrays.
  auto vertex = [](const std::vector<double>& x, int stride, size_t v) {
    return Vec3{x[stride * v], x[stride * v + 1], x[stride * v + 2]};
  };
  auto store = [](std::vector<float>& x, int stride, size_t v, const Vec3& value) {
    for (int k = 0; k < 3; ++k) x[stride * v + k] = static_cast<float>(value[k]);
  };
  // A direction through the linear part of 'm', normalized; 'len' is its length before (a zero
  // direction stays zero).
  auto unit = [](const Affine& m, const Vec3& d, double& len) {
    const Vec3 x = m.vector(d);
    len = length(x);
    return len > 0 ? x / len : x;
  };
  mesh.positions.resize(3 * nv);
  for (size_t v = 0; v < nv; ++v) {
    const Vec3 p = world.point(vertex(a.pos, 3, v));
    if (!in_traceable_range(p)) fail(c, af + "POSITION", "position out of range after transform");
    store(mesh.positions, 3, v, p);
  }
  if (!a.nrm.empty()) {
    mesh.normals.resize(3 * nv);
    for (size_t v = 0; v < nv; ++v) {
      double len = 0;
      const Vec3 n = unit(nm, vertex(a.nrm, 3, v), len);
      if (!(len > 0)) fail(c, af + "NORMAL", "zero normal at vertex " + std::to_string(v));
      store(mesh.normals, 3, v, n);
    }
  }
  if (!a.tan.empty()) {
    mesh.tangents.resize(4 * nv);
    for (size_t v = 0; v < nv; ++v) {
      double len = 0;
      store(mesh.tangents, 4, v, unit(world, vertex(a.tan, 4, v), len));
      // A mirroring transform flips the handedness of the tangent frame.
      mesh.tangents[4 * v + 3] =
          static_cast<float>((a.tan[4 * v + 3] < 0 ? -1.0 : 1.0) * (det < 0 ? -1 : 1));
    }
  }
  if (!a.uv.empty()) mesh.uvs.assign(a.uv.begin(), a.uv.end());
}

// A TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive: one mesh of c.out.
void load_triangles(const Ctx& c, const tinygltf::Primitive& prim, const Affine& world,
                    const std::vector<std::string>& names, const std::string& field) {
  const std::string af = field + ".attributes.";
  const VertexAttributes a = read_vertex_attributes(c, prim, af);
  std::vector<uint32_t> tri = triangle_indices(c, prim, a.pos.size() / 3, field);
  const double det = world.det();
  if (!std::isfinite(det) || std::abs(det) < 1e-300) fail(c, field, "node transform is singular");
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->material = material_key(c, prim.material, field + ".material");
  mesh->names = names;
  transform_vertices(c, a, world, det, af, *mesh);
  // A mirroring transform reverses the winding; swap to keep counter-clockwise = front.
  if (det < 0)
    for (size_t t = 0; t + 2 < tri.size(); t += 3) std::swap(tri[t + 1], tri[t + 2]);
  mesh->indices = std::move(tri);
  derive_tangents(*mesh);
  c.out->meshes.push_back(std::move(mesh));
}

}  // namespace

std::string material_key(const Ctx& c, int material, const std::string& field) {
  if (material < 0) return "";
  if (static_cast<size_t>(material) >= c.model.materials.size())
    fail(c, field, "material index " + std::to_string(material) + " out of range");
  const auto& name = c.model.materials[material].name;
  return name.empty() ? "material_" + std::to_string(material) : name;
}

void load_primitive(const Ctx& c, const tinygltf::Primitive& prim, const Affine& world,
                    const std::vector<std::string>& names, const std::string& field,
                    const std::string& node_field, FiberCurves& curves) {
  if (prim.mode >= 0 && prim.mode <= 3) {
    const bool radius = prim.attributes.count("_RADIUS") > 0;
    if (radius && prim.mode == TINYGLTF_MODE_LINE_STRIP) {
      load_curve(c, prim, world, field, node_field, curves);
      return;
    }
    c.out->warnings.push_back(c.file + ": " + field +
                              (radius ? ": fibers must be LINE_STRIP primitives (mode 3); skipped"
                                      : ": points/lines carry no area; skipped"));
    return;
  }
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN && prim.mode != -1)
    fail(c, field + ".mode", "unknown primitive mode " + std::to_string(prim.mode));
  load_triangles(c, prim, world, names, field);
}

}  // namespace weft::gltf_detail
