#pragma once
// The glTF loader's shared parts: gltf.cpp reads the file, its materials and its node trees;
// gltf_mesh.cpp the accessors, triangle meshes and fiber curves; gltf_lights.cpp the lights.
#include <tiny_gltf.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/vec.h"
#include "weft/scenes/gltf.h"

namespace weft::gltf_detail {

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

[[noreturn]] inline void fail(const Ctx& c, const std::string& field, const std::string& msg) {
  throw Error(c.file, field, msg);
}

inline bool finite_all(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// The binding key of glTF material 'material' (its name, else "material_<index>"; "" for none).
std::string material_key(const Ctx& c, int material, const std::string& field);

// A primitive of a mesh instance under node transform 'world': triangles become a mesh of
// c.out named 'names', a LINE_STRIP with _RADIUS one fiber of 'curves'; other points and lines
// are skipped with a warning.
void load_primitive(const Ctx& c, const tinygltf::Primitive& prim, const Affine& world,
                    const std::vector<std::string>& names, const std::string& field,
                    const std::string& node_field, FiberCurves& curves);

// The node's KHR_lights_punctual light, if it has one, into c.out (radiometric).
void load_light(const Ctx& c, const tinygltf::Node& node, const Affine& world,
                const std::string& field);

}  // namespace weft::gltf_detail
