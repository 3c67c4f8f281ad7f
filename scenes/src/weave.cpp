#include "weft/scenes/weave.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {
namespace {

constexpr double kMetresPerMm = 1e-3;

void check(const WeaveParams& p) {
  auto bad = [](const std::string& field, const std::string& msg) { throw Error("", field, msg); };
  if (p.pattern != "plain") bad("pattern", "unknown pattern '" + p.pattern + "' (valid: plain)");
  if (p.yarns < 1 || p.yarns > 4096) bad("yarns", "must lie in [1, 4096]");
  if (!(std::isfinite(p.yarn_radius_mm) && p.yarn_radius_mm > 0 && p.yarn_radius_mm < 1e3))
    bad("yarn-radius-mm", "must be finite and in (0, 1000)");
  if (!(std::isfinite(p.spacing_mm) && p.spacing_mm < 1e4)) bad("spacing-mm", "must be finite");
  if (!(p.spacing_mm >= 2 * p.yarn_radius_mm))
    bad("spacing-mm", "must be at least twice the yarn radius (parallel yarns would overlap)");
  if (p.segments < 2 || p.segments > (1 << 20)) bad("segments", "must lie in [2, 2^20]");
  if (p.sides < 3 || p.sides > 1024) bad("sides", "must lie in [3, 1024]");
  if (!std::isfinite(p.amplitude_mm) || p.amplitude_mm > 1e3) bad("amplitude-mm", "must be finite");
  const double tris = 2.0 * p.yarns * p.segments * p.sides * 2.0;
  if (tris > 2e9) bad("segments", "the patch would exceed 2e9 triangles");
}

void push3(std::vector<float>& v, const Vec3& p) {
  v.push_back(static_cast<float>(p.x));
  v.push_back(static_cast<float>(p.y));
  v.push_back(static_cast<float>(p.z));
}

// Appends one tube around a sinusoidal centre line. 'along' is the yarn axis, 'across' the
// in-plane offset axis of this yarn, 'offset' its position there; the centre line rises along y
// as sign * A * cos(pi (s - s0) / S).
void append_yarn(TriangleMesh& m, const WeaveParams& p, const Vec3& along, const Vec3& across,
                 double offset, double sign) {
  const double S = p.spacing_mm * kMetresPerMm, R = p.yarn_radius_mm * kMetresPerMm;
  const double A = (p.amplitude_mm < 0 ? p.yarn_radius_mm : p.amplitude_mm) * kMetresPerMm;
  const double L = p.yarns * S, s0 = -0.5 * (p.yarns - 1) * S;
  const Vec3 up{0, 1, 0};
  // U is perpendicular to the plane of the centre line; V = T x U completes the frame.
  const Vec3 U = cross(along, up);
  const auto base = static_cast<uint32_t>(m.vertex_count());
  const int K = p.segments, M = p.sides;
  for (int k = 0; k <= K; ++k) {
    const double s = -0.5 * L + L * k / K;
    const double phase = kPi * (s - s0) / S;
    const Vec3 c = along * s + across * offset + up * (sign * A * std::cos(phase));
    const Vec3 T = normalize(along + up * (-sign * A * (kPi / S) * std::sin(phase)));
    const Vec3 V = cross(T, U);
    for (int j = 0; j <= M; ++j) {
      const double th = 2 * kPi * (j % M) / M;  // the seam repeats the first column exactly
      const Vec3 r = U * std::cos(th) + V * std::sin(th);
      push3(m.positions, c + r * R);
      push3(m.normals, r);
      push3(m.tangents, T);
      // glTF: bitangent = cross(normal, tangent) * w; dP/dv points along -cross(r, T).
      m.tangents.push_back(-1.0f);
      m.uvs.push_back(static_cast<float>(static_cast<double>(k) / K));
      m.uvs.push_back(static_cast<float>(static_cast<double>(j) / M));
    }
  }
  for (int k = 0; k < K; ++k)
    for (int j = 0; j < M; ++j) {
      const uint32_t a = base + k * (M + 1) + j, b = a + (M + 1), c = b + 1, d = a + 1;
      // (a, d, b) and (b, d, c) wind counter-clockwise seen from outside the tube.
      m.indices.insert(m.indices.end(), {a, d, b, b, d, c});
    }
}

std::string base64(const std::vector<uint8_t>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  for (size_t i = 0; i < data.size(); i += 3) {
    const uint32_t n = (uint32_t(data[i]) << 16) |
                       (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0) |
                       (i + 2 < data.size() ? uint32_t(data[i + 2]) : 0);
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < data.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < data.size() ? table[n & 63] : '=';
  }
  return out;
}

// Builds the glTF JSON and its single binary buffer.
std::pair<nlohmann::json, std::vector<uint8_t>> build_document(const WeaveParams& p) {
  const auto meshes = make_weave(p);
  nlohmann::json doc;
  std::vector<uint8_t> bin;
  doc["asset"] = {{"version", "2.0"}, {"generator", "weft weave"}};
  doc["extras"] = {{"weft_weave",
                    {{"pattern", p.pattern},
                     {"yarns", p.yarns},
                     {"yarn_radius_mm", p.yarn_radius_mm},
                     {"spacing_mm", p.spacing_mm},
                     {"segments", p.segments},
                     {"sides", p.sides},
                     {"amplitude_mm", p.amplitude_mm < 0 ? p.yarn_radius_mm : p.amplitude_mm},
                     {"units", "metres"}}}};
  doc["scene"] = 0;
  doc["scenes"] = nlohmann::json::array({{{"name", "patch"}, {"nodes", {0}}}});
  doc["nodes"] = nlohmann::json::array({{{"name", "patch"}, {"children", {1, 2}}},
                                        {{"name", "warp"}, {"mesh", 0}},
                                        {{"name", "weft"}, {"mesh", 1}}});
  // Base colours only help other viewers; Weft binds its own materials by these names.
  doc["materials"] = nlohmann::json::array(
      {{{"name", "warp"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.1, 0.1, 1.0}}}}},
       {{"name", "weft"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}}}}});
  auto views = nlohmann::json::array(), accessors = nlohmann::json::array(),
       gmeshes = nlohmann::json::array();
  auto add_view = [&](const void* data, size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t off = bin.size();
    bin.resize(off + bytes);
    if (bytes) std::memcpy(bin.data() + off, data, bytes);
    views.push_back(
        {{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes}, {"target", target}});
    return views.size() - 1;
  };
  auto add_floats = [&](const std::vector<float>& v, int comps, const char* type, bool minmax) {
    nlohmann::json a = {{"bufferView", add_view(v.data(), v.size() * 4, 34962)},
                        {"componentType", 5126},
                        {"count", v.size() / comps},
                        {"type", type}};
    if (minmax) {
      std::vector<double> lo(comps, 1e300), hi(comps, -1e300);
      for (size_t i = 0; i < v.size(); ++i) {
        lo[i % comps] = std::min(lo[i % comps], double(v[i]));
        hi[i % comps] = std::max(hi[i % comps], double(v[i]));
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  };
  for (size_t mi = 0; mi < meshes.size(); ++mi) {
    const auto& m = meshes[mi];
    nlohmann::json attrs = {{"POSITION", add_floats(m.positions, 3, "VEC3", true)},
                            {"NORMAL", add_floats(m.normals, 3, "VEC3", false)},
                            {"TANGENT", add_floats(m.tangents, 4, "VEC4", false)},
                            {"TEXCOORD_0", add_floats(m.uvs, 2, "VEC2", false)}};
    size_t iv;
    int ctype;
    if (m.vertex_count() <= 65535) {
      std::vector<uint16_t> idx(m.indices.begin(), m.indices.end());
      iv = add_view(idx.data(), idx.size() * 2, 34963);
      ctype = 5123;
    } else {
      iv = add_view(m.indices.data(), m.indices.size() * 4, 34963);
      ctype = 5125;
    }
    accessors.push_back({{"bufferView", iv},
                         {"componentType", ctype},
                         {"count", m.indices.size()},
                         {"type", "SCALAR"}});
    gmeshes.push_back({{"name", m.material + "_yarns"},
                       {"primitives",
                        {{{"attributes", attrs},
                          {"indices", accessors.size() - 1},
                          {"material", mi},
                          {"mode", 4}}}}});
  }
  while (bin.size() % 4) bin.push_back(0);
  doc["meshes"] = gmeshes;
  doc["accessors"] = accessors;
  doc["bufferViews"] = views;
  doc["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
  return {doc, bin};
}

}  // namespace

std::vector<TriangleMesh> make_weave(const WeaveParams& p) {
  check(p);
  const double S = p.spacing_mm * kMetresPerMm;
  const double first = -0.5 * (p.yarns - 1) * S;
  TriangleMesh warp, weft;
  warp.material = "warp";
  warp.names = {"warp", "patch"};
  weft.material = "weft";
  weft.names = {"weft", "patch"};
  // Warp j runs along x at z_j; weft i along z at x_i. At crossing (i, j) the warp centre is at
  // +A (-1)^(i+j) and the weft centre at -A (-1)^(i+j): they alternate over and under.
  for (int j = 0; j < p.yarns; ++j)
    append_yarn(warp, p, {1, 0, 0}, {0, 0, 1}, first + j * S, (j % 2) ? -1.0 : 1.0);
  for (int i = 0; i < p.yarns; ++i)
    append_yarn(weft, p, {0, 0, 1}, {1, 0, 0}, first + i * S, (i % 2) ? 1.0 : -1.0);
  return {std::move(warp), std::move(weft)};
}

std::string weave_to_gltf(const WeaveParams& p) {
  auto [doc, bin] = build_document(p);
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
  return doc.dump(1) + "\n";
}

std::vector<uint8_t> weave_to_glb(const WeaveParams& p) {
  const auto [doc, bin] = build_document(p);
  std::string json = doc.dump();
  while (json.size() % 4) json += ' ';
  std::vector<uint8_t> out;
  auto u32 = [&](uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<uint8_t>(v >> (8 * k)));
  };
  u32(0x46546C67);  // "glTF"
  u32(2);
  u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);  // "JSON"
  out.insert(out.end(), json.begin(), json.end());
  u32(static_cast<uint32_t>(bin.size()));
  u32(0x004E4942);  // "BIN\0"
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

void write_weave(const std::filesystem::path& path, const WeaveParams& params) {
  const auto ext = path.extension().string();
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path.string(), "", "output must end in .gltf or .glb");
  if (ext == ".gltf") {
    write_text_atomically(path, weave_to_gltf(params));
    return;
  }
  const auto bytes = weave_to_glb(params);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw Error(path.string(), "", "write failed");
  });
}

}  // namespace weft
