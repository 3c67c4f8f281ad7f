// The OpenEXR pieces the table formats share (exr_io.h).
#include "exr_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVersion.h>

#include <cstring>
#include <fstream>
#include <set>

#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/spectrum.h"

namespace weft::exr_io {

// Walks the OpenEXR header (magic, version, then attributes "name\0type\0" int32 size, value,
// up to an empty name) before OpenEXR reads it: OpenEXR allocates what an attribute's size field
// claims, and the line offset table from the data window, before it checks either against the
// file (a 3 KB file whose string attribute claims 1.9 GB took 2 GB). Every size must fit in the
// bytes the file has, and the data window in max_width x max_height pixels.
void check_header(const std::filesystem::path& path, const std::string& file, int64_t max_width,
                  int64_t max_height) {
  std::error_code ec;
  const uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(file, "", "cannot read: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8] = {};
  in.read(reinterpret_cast<char*>(head), 8);
  if (!in) throw Error(file, "", "truncated: no OpenEXR header");
  const uint32_t flags = head[5] | (head[6] << 8) | (head[7] << 16);  // the version field >> 8
  if (head[4] != 2) throw Error(file, "version", "OpenEXR file version must be 2");
  if (flags & 0x18)  // bits 11 (deep data) and 12 (several parts) of the version field
    throw Error(file, "version", "a table is a single-part flat image (no deep data, one part)");
  const size_t max_name = (flags & 0x4) ? 255 : 31;  // bit 10: long names
  auto read_name = [&](const char* what) {
    std::string s;
    for (int c; (c = in.get()) != 0;) {
      if (c == EOF)
        throw Error(file, "", std::string("truncated header (in an attribute ") + what + ")");
      if (s.size() >= max_name)
        throw Error(file, "",
                    std::string("attribute ") + what + " longer than " + std::to_string(max_name) +
                        " characters");
      s += static_cast<char>(c);
    }
    return s;
  };
  for (int count = 0;; ++count) {
    const std::string name = read_name("name");
    if (name.empty()) break;
    if (count >= 1000) throw Error(file, "", "more than 1000 header attributes");
    const std::string type = read_name("type");
    unsigned char sz[4] = {};
    in.read(reinterpret_cast<char*>(sz), 4);
    if (!in) throw Error(file, name, "truncated header (attribute size)");
    const int32_t size =
        static_cast<int32_t>(sz[0] | (sz[1] << 8) | (sz[2] << 16) | (uint32_t(sz[3]) << 24));
    const uint64_t at = static_cast<uint64_t>(in.tellg());
    if (size < 0 || at + static_cast<uint64_t>(size) > file_size)
      throw Error(file, name,
                  "header attribute claims " + std::to_string(size) + " bytes; the file has " +
                      std::to_string(file_size > at ? file_size - at : 0) + " left");
    // OpenEXR reads a value of a known type at the type's size whatever the size field says,
    // and then reads the next attribute out of step (found by fuzz_table_exr: a dataWindow of
    // size 272 became a window of 458752 pixels a side, 2 GB of line buffers).
    static const std::pair<const char*, int> kFixed[] = {
        {"int", 4},      {"float", 4},       {"double", 8},         {"v2i", 8},
        {"v2f", 8},      {"v3i", 12},        {"v3f", 12},           {"box2i", 16},
        {"box2f", 16},   {"compression", 1}, {"lineOrder", 1},      {"envmap", 1},
        {"m33f", 36},    {"m44f", 64},       {"tiledesc", 9},       {"rational", 8},
        {"timecode", 8}, {"keycode", 28},    {"chromaticities", 32}};
    for (const auto& [t, bytes] : kFixed)
      if (type == t && size != bytes)
        throw Error(file, name,
                    "a " + type + " attribute holds " + std::to_string(bytes) +
                        " bytes; its size field says " + std::to_string(size));
    // A table has at most 33 channels of names up to 31 characters (48 bytes each in "chlist").
    if (type == "chlist" && size > 4096)
      throw Error(file, name,
                  "channel list of " + std::to_string(size) + " bytes: too many channels");
    if (name == "dataWindow" && type != "box2i")
      throw Error(file, name, "must be a box2i, not " + type);
    if (name == "dataWindow") {
      unsigned char b[16];
      in.read(reinterpret_cast<char*>(b), 16);
      int64_t v[4];
      for (int i = 0; i < 4; ++i)
        v[i] = static_cast<int32_t>(b[4 * i] | (b[4 * i + 1] << 8) | (b[4 * i + 2] << 16) |
                                    (uint32_t(b[4 * i + 3]) << 24));
      if (v[0] != 0 || v[1] != 0 || v[2] < 0 || v[3] < 0 || v[2] >= max_width || v[3] >= max_height)
        throw Error(file, "dataWindow",
                    "must start at (0, 0) and hold at most " + std::to_string(max_width) + " x " +
                        std::to_string(max_height) + " pixels (the largest table)");
    } else if (type == "chlist") {
      // OpenEXR reads channels up to an empty name, not by the size: both must end together.
      for (int channels = 0;; ++channels) {
        if (read_name("channel name").empty()) break;
        if (channels >= 64) throw Error(file, name, "more than 64 channels");
        in.seekg(16, std::ios::cur);  // pixel type, linear flag, reserved, x and y sampling
        if (!in || static_cast<uint64_t>(in.tellg()) > at + size) break;
      }
      if (!in || static_cast<uint64_t>(in.tellg()) != at + static_cast<uint64_t>(size))
        throw Error(file, name, "channel list does not match its size field");
    } else if (type == "preview") {
      // OpenEXR allocates 4 x width x height bytes from the two numbers in front.
      unsigned char wh[8] = {};
      in.read(reinterpret_cast<char*>(wh), 8);
      const uint64_t w = wh[0] | (wh[1] << 8) | (wh[2] << 16) | (uint64_t(wh[3]) << 24);
      const uint64_t h = wh[4] | (wh[5] << 8) | (wh[6] << 16) | (uint64_t(wh[7]) << 24);
      if (!in || w > 65535 || h > 65535 || 8 + 4 * w * h != static_cast<uint64_t>(size))
        throw Error(file, name, "preview image does not match its size field");
      in.seekg(size - 8, std::ios::cur);
    } else {
      in.seekg(size, std::ios::cur);
    }
    if (!in) throw Error(file, name, "truncated header");
  }
}

// The file must exist and begin with OpenEXR's magic number.
void check_magic(const std::filesystem::path& path, const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file, "", "no such table file");
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  if (!in || !Imf::isImfMagic(magic)) throw Error(file, "", "not an OpenEXR file");
}

int int_attribute(const Imf::Header& h, const std::string& file, const char* name) {
  const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name);
  if (!a) throw Error(file, name, "missing int attribute");
  return a->value();
}

std::string string_attribute(const Imf::Header& h, const std::string& file, const char* name) {
  const auto* a = h.findTypedAttribute<Imf::StringAttribute>(name);
  if (!a) throw Error(file, name, "missing string attribute");
  return a->value();
}

// The file's channels must be exactly 'names', each 32-bit FLOAT.
void check_channels(const Imf::Header& h, const std::string& file,
                    const std::vector<std::string>& names, const std::string& bands) {
  const std::set<std::string> wanted(names.begin(), names.end());
  std::set<std::string> present;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    const std::string name = it.name();
    if (!wanted.count(name))
      throw Error(file, "channels", "unexpected channel \"" + name + "\" for bands " + bands);
    if (it.channel().type != Imf::FLOAT)
      throw Error(file, "channels", "channel \"" + name + "\" is not 32-bit FLOAT");
    present.insert(name);
  }
  for (const auto& name : names)
    if (!present.count(name)) throw Error(file, "channels", "missing channel \"" + name + "\"");
}

void check_data_window(const Imf::Header& h, const std::string& file, int width, int height,
                       const std::string& why) {
  const Imath::Box2i dw = h.dataWindow();
  if (dw.min.x != 0 || dw.min.y != 0 || dw.max.x != width - 1 || dw.max.y != height - 1)
    throw Error(file, "dataWindow",
                "must be " + std::to_string(width) + " x " + std::to_string(height) +
                    " pixels from (0, 0) for " + why);
}

void check_fits_file(const std::filesystem::path& path, const std::string& file,
                     const std::string& field, double pixel_bytes, const std::string& what) {
  // write_image compresses with ZIP, and deflate expands at most 1032:1 (zlib's technical
  // details), so a 3 KB file cannot hold a 553 MB table (R = 32, 33 bands).
  std::error_code size_ec;
  const double file_bytes = double(std::filesystem::file_size(path, size_ec));
  if (pixel_bytes > 1032.0 * file_bytes + 65536)
    throw Error(file, field,
                what + " need " + std::to_string(static_cast<uint64_t>(pixel_bytes)) +
                    " bytes of pixels, more than a file of " +
                    std::to_string(static_cast<uint64_t>(file_bytes)) +
                    " bytes can hold (truncated?)");
}

namespace {

// One slice per channel over interleaved floats [row][column][channel].
Imf::FrameBuffer interleaved(const std::vector<std::string>& names, int width, float* values) {
  Imf::FrameBuffer fb;
  const size_t x_stride = sizeof(float) * names.size();
  const size_t y_stride = x_stride * static_cast<size_t>(width);
  char* base = reinterpret_cast<char*>(values);
  for (size_t c = 0; c < names.size(); ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + sizeof(float) * c, x_stride, y_stride));
  return fb;
}

}  // namespace

std::vector<float> read_pixels(Imf::InputFile& in, const std::string& file,
                               const std::vector<std::string>& names, int width, int height) {
  std::vector<float> values(static_cast<size_t>(width) * height * names.size(), 0.0f);
  const std::string stored_checksum = string_attribute(in.header(), file, "values_fnv1a64");
  in.setFrameBuffer(interleaved(names, width, values.data()));
  if (!in.isComplete()) throw Error(file, "", "truncated: pixel data incomplete");
  in.readPixels(0, height - 1);
  if (checksum(values) != stored_checksum)
    throw Error(file, "values_fnv1a64",
                "pixel data is corrupt (checksum " + checksum(values) + " does not match " +
                    stored_checksum + ")");
  return values;
}

void write_image(const std::filesystem::path& tmp, Imf::Header& header,
                 const std::vector<std::string>& names, const std::vector<float>& values) {
  const Imath::Box2i dw = header.dataWindow();
  const int width = dw.max.x + 1, height = dw.max.y + 1;
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  header.insert("values_fnv1a64", Imf::StringAttribute(checksum(values)));
  // OpenEXR's Slice wants a mutable pointer even for writing; it only reads through it.
  Imf::OutputFile out(tmp.c_str(), header);
  out.setFrameBuffer(interleaved(names, width, const_cast<float*>(values.data())));
  out.writePixels(height);
}

std::map<std::string, std::string> string_attributes(
    const Imf::Header& h, const std::function<bool(const std::string&)>& reserved) {
  std::map<std::string, std::string> out;
  for (auto it = h.begin(); it != h.end(); ++it) {
    const std::string name = it.name();
    if (reserved(name)) continue;
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
      out[name] = s->value();
  }
  return out;
}

std::string checksum(std::span<const float> values) {
  uint64_t h = kFnv1a64Basis;
  for (const float v : values) {
    uint32_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    unsigned char bytes[4];
    for (int k = 0; k < 4; ++k) bytes[k] = static_cast<unsigned char>((bits >> (8 * k)) & 0xffu);
    h = fnv1a64(bytes, 4, h);  // little-endian bytes whatever the host's order
  }
  return hex64(h);
}

std::vector<std::string> channel_names(int channels) {
  if (channels == 3) return {"R", "G", "B"};
  std::vector<std::string> names;
  for (int b = 0; b < channels; ++b) {
    // Appending (rather than "w" + ...) sidesteps GCC 12's false -Wrestrict (PR 105329).
    std::string name(1, 'w');
    name += std::to_string(static_cast<int>(band_wavelength_nm(b)));
    names.push_back(std::move(name));
  }
  return names;
}

}  // namespace weft::exr_io
