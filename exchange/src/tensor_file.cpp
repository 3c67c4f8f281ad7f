#include "tensor_file.h"

#include <bit>
#include <cstring>

#include "weft/core/error.h"

namespace weft::rgl {
namespace {

static_assert(std::endian::native == std::endian::little, "the tensor file is little-endian");

void put_bytes(std::vector<uint8_t>& out, const void* data, size_t n) {
  const size_t at = out.size();
  out.resize(at + n);
  if (n > 0) std::memcpy(out.data() + at, data, n);
}
template <class T>
void put(std::vector<uint8_t>& out, T v) {
  put_bytes(out, &v, sizeof(T));
}

}  // namespace

TensorField float_field(const std::string& name, std::vector<uint64_t> shape,
                        const std::vector<float>& values) {
  uint64_t n = 1;
  for (uint64_t s : shape) n *= s;
  if (n != values.size()) throw Error("", name, "shape does not match the number of values");
  TensorField f{name, kFloat32, std::move(shape), {}};
  f.bytes.resize(values.size() * sizeof(float));
  std::memcpy(f.bytes.data(), values.data(), f.bytes.size());
  return f;
}

TensorField byte_field(const std::string& name, const std::string& bytes) {
  return {name, kUInt8, {bytes.size()}, std::vector<uint8_t>(bytes.begin(), bytes.end())};
}

std::vector<uint8_t> encode_tensor_file(const std::vector<TensorField>& fields) {
  std::vector<uint8_t> out;
  const char magic[12] = "tensor_file";  // 11 characters and the terminating zero
  put_bytes(out, magic, 12);
  put<uint8_t>(out, 1);
  put<uint8_t>(out, 0);
  put<uint32_t>(out, static_cast<uint32_t>(fields.size()));
  std::vector<size_t> offset_at;
  for (const auto& f : fields) {
    put<uint16_t>(out, static_cast<uint16_t>(f.name.size()));
    put_bytes(out, f.name.data(), f.name.size());
    put<uint16_t>(out, static_cast<uint16_t>(f.shape.size()));
    put<uint8_t>(out, f.dtype);
    offset_at.push_back(out.size());
    put<uint64_t>(out, 0);  // patched below
    for (uint64_t s : f.shape) put<uint64_t>(out, s);
  }
  for (size_t k = 0; k < fields.size(); ++k) {
    out.resize((out.size() + 7) / 8 * 8, 0);
    const uint64_t offset = out.size();
    std::memcpy(out.data() + offset_at[k], &offset, sizeof offset);
    put_bytes(out, fields[k].bytes.data(), fields[k].bytes.size());
  }
  return out;
}

}  // namespace weft::rgl
