#pragma once
// The project's one content hash: 64-bit FNV-1a (Fowler, Noll and Vo; offset basis
// 14695981039346656037, prime 1099511628211). Not cryptographic: it names contents (spec hashes,
// table checksums, bake-cache keys) so that equal inputs give equal names.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace weft {

inline constexpr uint64_t kFnv1a64Basis = 14695981039346656037ULL;
inline constexpr uint64_t kFnv1a64Prime = 1099511628211ULL;

// Continues a hash 'h' over 'size' bytes (start from kFnv1a64Basis).
constexpr uint64_t fnv1a64(const unsigned char* bytes, size_t size, uint64_t h = kFnv1a64Basis) {
  for (size_t i = 0; i < size; ++i) {
    h ^= bytes[i];
    h *= kFnv1a64Prime;
  }
  return h;
}
inline uint64_t fnv1a64(std::string_view text, uint64_t h = kFnv1a64Basis) {
  return fnv1a64(reinterpret_cast<const unsigned char*>(text.data()), text.size(), h);
}

// 16 lower-case hex digits.
std::string hex64(uint64_t value);
// Bytes as base64 (RFC 4648, padded): glTF data URIs.
std::string base64(std::span<const uint8_t> data);

}  // namespace weft
