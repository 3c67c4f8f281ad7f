// OpenEXR reading and writing of TabulatedBsdfTable (format described in bsdf_table.h).
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVersion.h>

#include <fstream>
#include <set>
#include <string>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// Walks the OpenEXR header (magic, version, then attributes "name\0type\0" int32 size, value,
// up to an empty name) before OpenEXR reads it: OpenEXR allocates what an attribute's size field
// claims, and the line offset table from the data window, before it checks either against the
// file (a 3 KB file whose string attribute claims 1.9 GB took 2 GB). Every size must fit in the
// bytes the file has, and the data window in the largest table.
void check_exr_header(const std::filesystem::path& path, const std::string& file) {
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
  const int64_t max_pixel = 2 * int64_t{TabulatedBsdfTable::kMaxResolution} *
                            TabulatedBsdfTable::kMaxResolution;  // bins of the largest table
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
      if (v[0] != 0 || v[1] != 0 || v[2] < 0 || v[3] < 0 || v[2] >= max_pixel || v[3] >= max_pixel)
        throw Error(file, "dataWindow",
                    "must start at (0, 0) and hold at most " + std::to_string(max_pixel) +
                        " pixels a side (the largest table)");
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
void check_exr_magic(const std::filesystem::path& path, const std::string& file) {
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

// The table's format from the header: version, parameterization, units, kind, resolution and
// bands (returned, as the file spells them).
std::string read_table_format(const Imf::Header& h, const std::string& file,
                              TabulatedBsdfTable& table) {
  using T = TabulatedBsdfTable;
  auto string_attr = [&](const char* name) { return string_attribute(h, file, name); };
  const int version = int_attribute(h, file, "weft_format_version");
  if (version == 1 || version == 2)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) +
                    ": an octahedral-grid table whose bins straddle the horizon; re-bake it with "
                    "this version (format " +
                    std::to_string(T::kFormatVersion) + ")");
  if (version != T::kFormatVersion)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) + "; this program reads version " +
                    std::to_string(T::kFormatVersion));
  if (string_attr("parameterization") != T::kParameterization)
    throw Error(file, "parameterization",
                "is \"" + string_attr("parameterization") + "\", expected \"" +
                    T::kParameterization + "\"");
  if (string_attr("units") != T::kUnits)
    throw Error(file, "units", "is \"" + string_attr("units") + "\", expected \"1/sr\"");
  table.kind = string_attr("kind");
  if (table.kind != "fiber" && table.kind != "fabric")
    throw Error(file, "kind", "must be \"fiber\" or \"fabric\", got \"" + table.kind + "\"");
  table.resolution = int_attribute(h, file, "resolution");
  if (table.resolution < 1 || table.resolution > T::kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(T::kMaxResolution) + "], got " +
                    std::to_string(table.resolution));
  const std::string bands = string_attr("bands");
  if (bands == "rgb") {
    table.channels = 3;
  } else if (bands == T::kSpectralBands) {
    table.channels = kNumBands;
  } else {
    throw Error(file, "bands", "must be \"rgb\" or \"390:710:10\", got \"" + bands + "\"");
  }
  return bands;
}

// The data window must be the table's, and the file large enough to hold its pixels.
void check_pixel_size(const Imf::Header& h, const std::filesystem::path& path,
                      const std::string& file, const TabulatedBsdfTable& table,
                      const std::string& bands) {
  const int n = table.bins();
  const Imath::Box2i dw = h.dataWindow();
  if (dw.min.x != 0 || dw.min.y != 0 || dw.max.x != n - 1 || dw.max.y != n - 1)
    throw Error(file, "dataWindow",
                "must be " + std::to_string(n) + " x " + std::to_string(n) +
                    " pixels from (0, 0) for resolution " + std::to_string(table.resolution));
  // The pixels must be in the file before their buffer is allocated: write_exr compresses with
  // ZIP, and deflate expands at most 1032:1 (zlib's technical details), so a 3 KB file cannot
  // hold a 553 MB table (R = 32, 33 bands).
  const double pixel_bytes = double(n) * n * table.channels * sizeof(float);
  std::error_code size_ec;
  const double file_bytes = double(std::filesystem::file_size(path, size_ec));
  if (pixel_bytes > 1032.0 * file_bytes + 65536)
    throw Error(file, "resolution",
                std::to_string(table.resolution) + " and bands " + bands + " need " +
                    std::to_string(static_cast<uint64_t>(pixel_bytes)) +
                    " bytes of pixels, more than a file of " +
                    std::to_string(static_cast<uint64_t>(file_bytes)) +
                    " bytes can hold (truncated?)");
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

// The pixels of channels 'names' into table.values, checked against the stored checksum.
void read_table_pixels(Imf::InputFile& in, const std::string& file,
                       const std::vector<std::string>& names, TabulatedBsdfTable& table) {
  const int n = table.bins();
  table.values.assign(static_cast<size_t>(n) * n * table.channels, 0.0f);
  Imf::FrameBuffer fb;
  const size_t x_stride = sizeof(float) * static_cast<size_t>(table.channels);
  const size_t y_stride = x_stride * static_cast<size_t>(n);
  char* base = reinterpret_cast<char*>(table.values.data());
  for (int c = 0; c < table.channels; ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + sizeof(float) * c, x_stride, y_stride));
  const std::string stored_checksum = string_attribute(in.header(), file, "values_fnv1a64");
  in.setFrameBuffer(fb);
  if (!in.isComplete()) throw Error(file, "", "truncated: pixel data incomplete");
  in.readPixels(0, n - 1);
  if (table.checksum() != stored_checksum)
    throw Error(file, "values_fnv1a64",
                "pixel data is corrupt (checksum " + table.checksum() + " does not match " +
                    stored_checksum + ")");
}

}  // namespace

void TabulatedBsdfTable::check_output_path(const std::filesystem::path& path,
                                           const std::string& field) {
  if (path.extension() != ".exr")
    throw Error(path.string(), field,
                "a table is written as OpenEXR: the name must end in .exr, not '" +
                    path.extension().string() + "'");
  std::error_code ec;
  const auto dir = std::filesystem::absolute(path, ec).parent_path();
  if (ec || !std::filesystem::is_directory(dir, ec))
    throw Error(path.string(), field, "output directory does not exist");
}

void TabulatedBsdfTable::write_exr(const std::filesystem::path& path) const {
  const std::string file = path.string();
  check_output_path(path, "");
  validate(file);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      const int width = bins();
      Imf::Header header(width, width);
      header.compression() = Imf::ZIP_COMPRESSION;
      const std::vector<std::string> names = channel_names();
      for (const auto& name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      header.insert("weft_format_version", Imf::IntAttribute(kFormatVersion));
      header.insert("cell_average", Imf::StringAttribute(kCellAverage));
      header.insert("parameterization", Imf::StringAttribute(kParameterization));
      header.insert("resolution", Imf::IntAttribute(resolution));
      header.insert("bands", Imf::StringAttribute(bands()));
      header.insert("units", Imf::StringAttribute(kUnits));
      header.insert("kind", Imf::StringAttribute(kind));
      header.insert("values_fnv1a64", Imf::StringAttribute(checksum()));
      for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));

      Imf::FrameBuffer fb;
      const size_t x_stride = sizeof(float) * static_cast<size_t>(channels);
      const size_t y_stride = x_stride * static_cast<size_t>(width);
      // OpenEXR's Slice wants a mutable pointer even for writing; it only reads through it.
      char* base = reinterpret_cast<char*>(const_cast<float*>(values.data()));
      for (int c = 0; c < channels; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + sizeof(float) * c, x_stride, y_stride));
      Imf::OutputFile out(tmp.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(width);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw Error(file, "", std::string("cannot write the OpenEXR table: ") + e.what());
    }
  });
}

TabulatedBsdfTable TabulatedBsdfTable::read_exr(const std::filesystem::path& path) {
  const std::string file = path.string();
  check_exr_magic(path, file);
  check_exr_header(path, file);

  TabulatedBsdfTable table;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    const std::string bands = read_table_format(h, file, table);
    check_pixel_size(h, path, file, table, bands);
    const std::vector<std::string> names = table.channel_names();
    check_channels(h, file, names, bands);
    read_table_pixels(in, file, names, table);

    for (auto it = h.begin(); it != h.end(); ++it) {
      const std::string name = it.name();
      if (is_reserved_attribute(name)) continue;
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        table.metadata[name] = s->value();
    }
    if (string_attribute(h, file, "cell_average") != kCellAverage)
      throw Error(file, "cell_average",
                  "is \"" + string_attribute(h, file, "cell_average") +
                      "\"; this program reads \"" + kCellAverage + "\" cell averages");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("corrupt or truncated OpenEXR table: ") + e.what());
  }
  table.validate(file);
  return table;
}

}  // namespace weft
