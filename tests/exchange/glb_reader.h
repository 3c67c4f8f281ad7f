#pragma once
// Binary glTF read back without tinygltf, for the export tests (the .glb and the .html preview's
// embedded .glb): own chunk parsing, nlohmann for the JSON.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_util.h"

namespace weft::testing {

inline uint32_t le32(const std::string& d, size_t at) {
  uint32_t v = 0;
  for (int k = 0; k < 4; ++k)
    v |= static_cast<uint32_t>(static_cast<unsigned char>(d[at + k])) << (8 * k);
  return v;
}

// GLB (glTF 2.0 "Binary glTF"): 12-byte header 'glTF', version 2, length; chunk 0 JSON, chunk 1
// BIN; each chunk: length, type, data.
inline nlohmann::json read_glb_bytes(const std::string& d, std::string* bin) {
  EXPECT_EQ(d.substr(0, 4), "glTF");
  EXPECT_EQ(le32(d, 4), 2u);
  EXPECT_EQ(le32(d, 8), d.size());
  const uint32_t json_length = le32(d, 12);
  EXPECT_EQ(le32(d, 16), 0x4E4F534Au);  // "JSON"
  const size_t bin_at = 20 + json_length;
  EXPECT_EQ(le32(d, bin_at + 4), 0x004E4942u);  // "BIN\0"
  *bin = d.substr(bin_at + 8, le32(d, bin_at));
  return nlohmann::json::parse(d.substr(20, json_length));
}
inline nlohmann::json read_glb(const std::filesystem::path& p, std::string* bin) {
  return read_glb_bytes(slurp(p), bin);
}

// The floats of a FLOAT accessor (tightly packed, as the exporter writes them).
inline std::vector<float> accessor_floats(const nlohmann::json& j, const std::string& bin,
                                          int accessor) {
  const auto& a = j.at("accessors").at(accessor);
  const auto& v = j.at("bufferViews").at(a.at("bufferView").get<int>());
  const size_t per = a.at("type") == "VEC3" ? 3 : a.at("type") == "VEC2" ? 2 : 1;
  std::vector<float> out(a.at("count").get<size_t>() * per);
  const size_t at = v.value("byteOffset", size_t{0}) + a.value("byteOffset", size_t{0});
  EXPECT_LE(at + out.size() * 4, bin.size());
  std::memcpy(out.data(), bin.data() + at, out.size() * 4);
  return out;
}

}  // namespace weft::testing
