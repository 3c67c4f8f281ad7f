#pragma once
// The tensor file of the RGL material database (Dupuy & Jakob 2018), which Mitsuba 3's and
// pbrt-v4's `measured` BSDFs read: "tensor_file\0" (12 bytes), version 1.0 (two uint8), the
// field count (uint32), then per field its name (uint16 length + UTF-8 bytes), rank (uint16),
// dtype (uint8: 1 uint8 ... 10 float32, 11 float64), byte offset of its data (uint64) and shape
// (uint64 per dimension); then the fields' data, each C-ordered and starting on an 8-byte boundary.
// Everything little-endian.
#include <cstdint>
#include <string>
#include <vector>

namespace weft::rgl {

inline constexpr uint8_t kUInt8 = 1;
inline constexpr uint8_t kFloat32 = 10;

struct TensorField {
  std::string name;
  uint8_t dtype = kFloat32;
  std::vector<uint64_t> shape;
  std::vector<uint8_t> bytes;  // the data, little-endian, C order
};
TensorField float_field(const std::string& name, std::vector<uint64_t> shape,
                        const std::vector<float>& values);
TensorField byte_field(const std::string& name, const std::string& bytes);

// The whole file's bytes.
std::vector<uint8_t> encode_tensor_file(const std::vector<TensorField>& fields);

}  // namespace weft::rgl
