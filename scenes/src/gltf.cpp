// glTF 2.0 loading. Debian's libtinygltf ships the implementation in a shared library, so this
// file only includes the header. Every index and byte range that tinygltf hands over is checked
// here before use: malformed files must end in a weft::Error, never in a crash.
#include "weft/scenes/gltf.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

// Affine transform: 3x3 linear part (row-major) and a translation.
struct Affine {
  std::array<std::array<double, 3>, 3> m{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  Vec3 t;

  Vec3 point(const Vec3& p) const { return vector(p) + t; }
  Vec3 vector(const Vec3& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  double det() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  // Inverse transpose of the linear part (for normals).
  Affine normal_matrix() const {
    const double d = det();
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        // cofactor(i, j) / det = (M^-1)^T(i, j)
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        r.m[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / d;
      }
    return r;
  }
  Affine operator*(const Affine& b) const {
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.m[i][j] = m[i][0] * b.m[0][j] + m[i][1] * b.m[1][j] + m[i][2] * b.m[2][j];
    r.t = point(b.t);
    return r;
  }
};

struct Ctx {
  const tinygltf::Model& model;
  std::string file;
  GltfContent* out;
  GltfLightUnits light_units = GltfLightUnits::photometric;
};

[[noreturn]] void fail(const Ctx& c, const std::string& field, const std::string& msg) {
  throw Error(c.file, field, msg);
}

// Largest |coordinate| (metres) of a vertex or light after the node transforms; farther points
// cannot be traced in Embree's single precision (camera.h states why).
constexpr double kMaxCoordinate_m = kMaxCameraCoordinate_m;

bool finite_all(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

std::string format_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string format_rgb(const Rgb& c) {
  return "(" + format_number(c.r) + ", " + format_number(c.g) + ", " + format_number(c.b) + ")";
}

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

std::string material_key(const Ctx& c, int material, const std::string& field) {
  if (material < 0) return "";
  if (static_cast<size_t>(material) >= c.model.materials.size())
    fail(c, field, "material index " + std::to_string(material) + " out of range");
  const auto& name = c.model.materials[material].name;
  return name.empty() ? "material_" + std::to_string(material) : name;
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
  auto attr = [&](const char* name) {
    const auto it = prim.attributes.find(name);
    return it == prim.attributes.end() ? -2 : it->second;
  };
  const std::string af = field + ".attributes.";
  if (attr("POSITION") == -2) fail(c, af + "POSITION", "is required");
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
    for (size_t i = 0; i < idx.size(); ++i)
      if (idx[i] >= nv)
        fail(c, field + ".indices",
             "index " + std::to_string(idx[i]) + " at " + std::to_string(i) +
                 " exceeds the vertex count " + std::to_string(nv));
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
    if (!is_finite(p) || std::abs(p.x) > kMaxCoordinate_m || std::abs(p.y) > kMaxCoordinate_m ||
        std::abs(p.z) > kMaxCoordinate_m)
      fail(c, af + "POSITION", "position out of range after transform");
    if (!(r > 0 && r < kMaxCoordinate_m))
      fail(c, af + "_RADIUS",
           "radius out of range after transform at element " + std::to_string(v));
    curves.points.insert(curves.points.end(),
                         {float(p.x), float(p.y), float(p.z), static_cast<float>(r)});
  }
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
  auto attr = [&](const char* name) {
    const auto it = prim.attributes.find(name);
    return it == prim.attributes.end() ? -2 : it->second;
  };
  const std::string af = field + ".attributes.";
  if (attr("POSITION") == -2) fail(c, af + "POSITION", "is required");
  const auto pos = read_attribute(c, attr("POSITION"), 3, false, af + "POSITION");
  const size_t nv = pos.size() / 3;
  std::vector<double> nrm, tan, uv;
  if (attr("NORMAL") != -2) nrm = read_attribute(c, attr("NORMAL"), 3, false, af + "NORMAL");
  if (attr("TANGENT") != -2) tan = read_attribute(c, attr("TANGENT"), 4, false, af + "TANGENT");
  if (attr("TEXCOORD_0") != -2)
    uv = read_attribute(c, attr("TEXCOORD_0"), 2, true, af + "TEXCOORD_0");
  if (!nrm.empty() && nrm.size() != 3 * nv) fail(c, af + "NORMAL", "count differs from POSITION");
  if (!tan.empty() && tan.size() != 4 * nv) fail(c, af + "TANGENT", "count differs from POSITION");
  if (!uv.empty() && uv.size() != 2 * nv) fail(c, af + "TEXCOORD_0", "count differs from POSITION");

  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    idx = read_indices(c, prim.indices, field + ".indices");
  } else {
    idx.resize(nv);
    for (size_t i = 0; i < nv; ++i) idx[i] = static_cast<uint32_t>(i);
  }
  for (size_t i = 0; i < idx.size(); ++i)
    if (idx[i] >= nv)
      fail(c, field + ".indices",
           "index " + std::to_string(idx[i]) + " at " + std::to_string(i) +
               " exceeds the vertex count " + std::to_string(nv));
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

  const double det = world.det();
  if (!std::isfinite(det) || std::abs(det) < 1e-300) fail(c, field, "node transform is singular");
  const Affine nm = world.normal_matrix();
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->material = material_key(c, prim.material, field + ".material");
  mesh->names = names;
  // Vertex v of a packed attribute ('stride' values per vertex) and of the mesh's float arrays.
  auto vertex = [](const std::vector<double>& a, int stride, size_t v) {
    return Vec3{a[stride * v], a[stride * v + 1], a[stride * v + 2]};
  };
  auto store = [](std::vector<float>& a, int stride, size_t v, const Vec3& x) {
    for (int k = 0; k < 3; ++k) a[stride * v + k] = static_cast<float>(x[k]);
  };
  // A direction through the linear part of 'm', normalized; 'len' is its length before (a zero
  // direction stays zero).
  auto unit = [](const Affine& m, const Vec3& d, double& len) {
    const Vec3 x = m.vector(d);
    len = length(x);
    return len > 0 ? x / len : x;
  };
  mesh->positions.resize(3 * nv);
  for (size_t v = 0; v < nv; ++v) {
    const Vec3 p = world.point(vertex(pos, 3, v));
    if (!is_finite(p) || std::abs(p.x) > kMaxCoordinate_m || std::abs(p.y) > kMaxCoordinate_m ||
        std::abs(p.z) > kMaxCoordinate_m)
      fail(c, af + "POSITION", "position out of range after transform");
    store(mesh->positions, 3, v, p);
  }
  if (!nrm.empty()) {
    mesh->normals.resize(3 * nv);
    for (size_t v = 0; v < nv; ++v) {
      double len = 0;
      const Vec3 n = unit(nm, vertex(nrm, 3, v), len);
      if (!(len > 0)) fail(c, af + "NORMAL", "zero normal at vertex " + std::to_string(v));
      store(mesh->normals, 3, v, n);
    }
  }
  if (!tan.empty()) {
    mesh->tangents.resize(4 * nv);
    for (size_t v = 0; v < nv; ++v) {
      double len = 0;
      store(mesh->tangents, 4, v, unit(world, vertex(tan, 4, v), len));
      // A mirroring transform flips the handedness of the tangent frame.
      mesh->tangents[4 * v + 3] =
          static_cast<float>((tan[4 * v + 3] < 0 ? -1.0 : 1.0) * (det < 0 ? -1 : 1));
    }
  }
  if (!uv.empty()) mesh->uvs.assign(uv.begin(), uv.end());
  // A mirroring transform reverses the winding; swap to keep counter-clockwise = front.
  if (det < 0)
    for (size_t t = 0; t + 2 < tri.size(); t += 3) std::swap(tri[t + 1], tri[t + 2]);
  mesh->indices = std::move(tri);
  derive_tangents(*mesh);
  c.out->meshes.push_back(std::move(mesh));
}

Rgb light_color(const Ctx& c, const tinygltf::Light& l, const std::string& field) {
  Rgb color(1.0);
  if (!l.color.empty()) {
    if (l.color.size() != 3 || !finite_all(l.color))
      fail(c, field + ".color", "needs 3 finite numbers");
    color = {l.color[0], l.color[1], l.color[2]};
  }
  if (!std::isfinite(l.intensity) || l.intensity < 0)
    fail(c, field + ".intensity", "must be finite and >= 0");
  if (color.r < 0 || color.g < 0 || color.b < 0) fail(c, field + ".color", "must be >= 0");
  return color * l.intensity;
}

void load_light(const Ctx& c, const tinygltf::Node& node, const Affine& world,
                const std::string& field) {
  const auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end()) return;
  const std::string ef = field + ".extensions.KHR_lights_punctual.light";
  if (!it->second.IsObject() || !it->second.Has("light") || !it->second.Get("light").IsNumber())
    fail(c, ef, "is required and must be a number");
  const int index = it->second.Get("light").GetNumberAsInt();
  if (index < 0 || static_cast<size_t>(index) >= c.model.lights.size())
    fail(c, ef, "light index " + std::to_string(index) + " out of range");
  const auto& l = c.model.lights[index];
  const std::string lf = "extensions.KHR_lights_punctual.lights[" + std::to_string(index) + "]";
  const Rgb color = light_color(c, l, lf);
  // Lights shine along their local -z.
  const Vec3 axis = world.vector({0, 0, -1});
  if (!(length(axis) > 0) || !is_finite(axis))
    fail(c, field, "light transform is singular or not finite");
  // KHR_lights_punctual intensities are photometric; Weft's lights are radiometric (lights.h).
  const bool photometric = c.light_units == GltfLightUnits::photometric;
  const Rgb radiometric = photometric ? color / kLuminousEfficacy_lm_per_W : color;
  const std::string what = lf + (l.name.empty() ? "" : " '" + l.name + "'") + " (" + l.type + ")";
  if (l.type == "directional") {
    c.out->lights.directional.push_back({-normalize(axis), radiometric});
    c.out->notes.push_back(c.file + ": " + what + ": " + format_number(l.intensity) +
                           (photometric ? " lux" : " (radiometric)") + " -> irradiance " +
                           format_rgb(radiometric) + " W/m^2");
  } else if (l.type == "point" || l.type == "spot") {
    PointLight p;
    p.position = world.point({0, 0, 0});
    if (!is_finite(p.position) || std::abs(p.position.x) > kMaxCoordinate_m ||
        std::abs(p.position.y) > kMaxCoordinate_m || std::abs(p.position.z) > kMaxCoordinate_m)
      fail(c, field, "light position out of range after transform");
    p.intensity = radiometric;
    c.out->notes.push_back(c.file + ": " + what + ": " + format_number(l.intensity) +
                           (photometric ? " cd" : " (radiometric)") + " -> radiant intensity " +
                           format_rgb(radiometric) + " W/sr");
    if (l.type == "spot") {
      const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
      if (!(inner >= 0 && inner < outer && outer <= kPi / 2))
        fail(c, lf + ".spot", "needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
      p.spot_direction = normalize(axis);
      p.cos_inner = std::cos(inner);
      p.cos_outer = std::cos(outer);
    }
    c.out->lights.points.push_back(p);
  } else {
    fail(c, lf + ".type", "unknown light type '" + l.type + "'");
  }
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

}  // namespace

GltfContent load_gltf(const std::filesystem::path& path, GltfLightUnits light_units) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file, "", "glTF file not found");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_images, nullptr);
  tinygltf::Model model;
  std::string err, warn;
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
  GltfContent out;
  out.files.push_back(path);
  for (const auto& b : model.buffers)
    if (!b.uri.empty() && b.uri.rfind("data:", 0) != 0) {
      // As tinygltf found it: relative to the glTF's folder, percent-escapes decoded.
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
      out.files.push_back(path.parent_path() / uri);
    }
  const Ctx c{model, file, &out, light_units};
  for (size_t i = 0; i < model.materials.size(); ++i) {
    const auto& mat = model.materials[i];
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
        fail(c, mf + ".extensions.KHR_materials_emissive_strength.emissiveStrength",
             "must be >= 0");
      info.emission *= s.GetNumberAsDouble();
    }
    if (info.emission.r < 0 || info.emission.g < 0 || info.emission.b < 0)
      fail(c, mf + ".emissiveFactor", "must be >= 0");
    out.materials[material_key(c, static_cast<int>(i), mf)] = info;
  }
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
    // No scene: every node that is nobody's child is a root.
    std::vector<uint8_t> is_child(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
      for (int ch : n.children)
        if (ch >= 0 && static_cast<size_t>(ch) < model.nodes.size()) is_child[ch] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  load_nodes(c, roots);
  ignored_content_warnings(c);
  for (auto& w : warn)
    if (w == '\n') w = ' ';
  if (!warn.empty()) out.warnings.push_back(file + ": " + warn);
  return out;
}

}  // namespace weft
