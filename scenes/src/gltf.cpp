// glTF 2.0 loading. Debian's libtinygltf ships the implementation in a shared library, so this
// file only includes the header. Every index and byte range that tinygltf hands over is checked
// here before use: malformed files must end in a weft::Error, never in a crash.
#include "weft/scenes/gltf.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"

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
};

[[noreturn]] void fail(const Ctx& c, const std::string& field, const std::string& msg) {
  throw Error(c.file, field, msg);
}

bool finite_all(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
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

// Where the bytes of accessor 'index' are, after checking every index and range.
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t count = 0, stride = 0;
  int component_type = 0, components = 0;
  bool normalized = false;
};

AccessorView accessor_view(const Ctx& c, int index, const std::string& field) {
  const auto& m = c.model;
  if (index < 0 || static_cast<size_t>(index) >= m.accessors.size())
    fail(c, field,
         "accessor index " + std::to_string(index) + " out of range (" +
             std::to_string(m.accessors.size()) + " accessors)");
  const auto& acc = m.accessors[index];
  const std::string af = "accessors[" + std::to_string(index) + "]";
  if (acc.sparse.isSparse) fail(c, af, "sparse accessors are not supported");
  if (acc.bufferView < 0 || static_cast<size_t>(acc.bufferView) >= m.bufferViews.size())
    fail(c, af + ".bufferView", "index " + std::to_string(acc.bufferView) + " out of range");
  const auto& view = m.bufferViews[acc.bufferView];
  const std::string vf = "bufferViews[" + std::to_string(acc.bufferView) + "]";
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m.buffers.size())
    fail(c, vf + ".buffer", "index " + std::to_string(view.buffer) + " out of range");
  const auto& buffer = m.buffers[view.buffer];
  const int csize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(acc.componentType));
  const int ncomp = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(acc.type));
  if (csize <= 0 || ncomp <= 0) fail(c, af, "unknown componentType or type");
  const int stride = acc.ByteStride(view);
  if (stride <= 0) fail(c, vf + ".byteStride", "invalid");
  const size_t elem = static_cast<size_t>(csize) * ncomp;
  if (static_cast<size_t>(stride) < elem) fail(c, vf + ".byteStride", "smaller than an element");
  if (view.byteOffset > buffer.data.size() ||
      view.byteLength > buffer.data.size() - view.byteOffset)
    fail(c, vf,
         "byte range exceeds buffer " + std::to_string(view.buffer) + " (" +
             std::to_string(buffer.data.size()) + " bytes)");
  if (acc.byteOffset > view.byteLength) fail(c, af + ".byteOffset", "exceeds its bufferView");
  if (acc.count > 0) {
    const size_t need = acc.byteOffset + (acc.count - 1) * static_cast<size_t>(stride) + elem;
    if (acc.count > (size_t(1) << 40) || need > view.byteLength)
      fail(c, af, "byte range exceeds its bufferView");
  }
  return {buffer.data.data() + view.byteOffset + acc.byteOffset,
          acc.count,
          static_cast<size_t>(stride),
          acc.componentType,
          ncomp,
          acc.normalized};
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
    if (!is_finite(p) || std::abs(p.x) > 1e30 || std::abs(p.y) > 1e30 || std::abs(p.z) > 1e30)
      fail(c, af + "POSITION", "position out of range after transform");
    if (!(r > 0 && r < 1e30))
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
    if (!is_finite(p) || std::abs(p.x) > 1e30 || std::abs(p.y) > 1e30 || std::abs(p.z) > 1e30)
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
  if (!(length(axis) > 0)) fail(c, field, "light transform is singular");
  if (l.type == "directional") {
    c.out->lights.directional.push_back({-normalize(axis), color});
  } else if (l.type == "point" || l.type == "spot") {
    PointLight p;
    p.position = world.point({0, 0, 0});
    p.intensity = color;
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
  if (!(length(cross(f, u)) > 0)) fail(c, field, "camera transform is singular");
  cam = Camera::look_at(Camera::Type::perspective, world.point({0, 0, 0}),
                        world.point({0, 0, 0}) + f, u);
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
  c.out->cameras.push_back({node.name.empty() ? gc.name : node.name, cam});
}

void visit(const Ctx& c, int index, const Affine& parent, std::vector<std::string> names,
           std::vector<uint8_t>& on_path) {
  const auto& m = c.model;
  const std::string field = "nodes[" + std::to_string(index) + "]";
  if (index < 0 || static_cast<size_t>(index) >= m.nodes.size())
    fail(c, field, "node index out of range (" + std::to_string(m.nodes.size()) + " nodes)");
  if (on_path[index]) fail(c, field, "node hierarchy has a cycle");
  on_path[index] = 1;
  const auto& node = m.nodes[index];
  const Affine world = parent * local_transform(c, node, field);
  if (!node.name.empty()) names.insert(names.begin(), node.name);  // own name first
  if (node.mesh >= 0) {
    if (static_cast<size_t>(node.mesh) >= m.meshes.size())
      fail(c, field + ".mesh", "mesh index " + std::to_string(node.mesh) + " out of range");
    const auto& mesh = m.meshes[node.mesh];
    auto mesh_names = names;
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
  for (int child : node.children) visit(c, child, world, names, on_path);
  on_path[index] = 0;
}

bool ignore_images(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                   const unsigned char*, int, void*) {
  return true;  // Weft binds its own materials; textures are not used.
}

}  // namespace

GltfContent load_gltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file, "", "glTF file not found");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_images, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = path.extension() == ".glb" || path.extension() == ".GLB";
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                : loader.LoadASCIIFromFile(&model, &err, &warn, file);
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("malformed glTF: ") + e.what());
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    throw Error(file, "", "malformed glTF: " + (err.empty() ? std::string("unknown error") : err));
  }
  GltfContent out;
  const Ctx c{model, file, &out};
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
    const int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<size_t>(s) >= model.scenes.size()) fail(c, "scene", "scene index out of range");
    roots = model.scenes[s].nodes;
  } else {
    // No scene: every node that is nobody's child is a root.
    std::vector<uint8_t> is_child(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
      for (int ch : n.children)
        if (ch >= 0 && static_cast<size_t>(ch) < model.nodes.size()) is_child[ch] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  std::vector<uint8_t> on_path(model.nodes.size(), 0);
  for (int r : roots) visit(c, r, Affine{}, {}, on_path);
  for (auto& w : warn)
    if (w == '\n') w = ' ';
  if (!warn.empty()) out.warnings.push_back(file + ": " + warn);
  return out;
}

}  // namespace weft
