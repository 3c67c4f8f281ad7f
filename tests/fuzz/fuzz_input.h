#pragma once
// What every harness shares: loaders that take a path get the input as a file of this process,
// and a harness accepts weft::Error (a clear message about bad input) and nothing else: any other
// exception escapes to libFuzzer and is reported as a crash.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace weft::fuzz {

// The bytes as a file named weft-fuzz-<pid><ext> in the temporary folder (one per process, so
// parallel jobs do not share it), rewritten for every input.
inline std::filesystem::path input_file(const uint8_t* data, size_t size, const char* ext) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("weft-fuzz-" + std::to_string(static_cast<long>(getpid())) + ext);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

inline std::string_view text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace weft::fuzz
