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

void TabulatedBsdfTable::write_exr(const std::filesystem::path& path) const {
  const std::string file = path.string();
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
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file, "", "no such table file");
  {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    if (!in || !Imf::isImfMagic(magic)) throw Error(file, "", "not an OpenEXR file");
  }

  TabulatedBsdfTable table;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    auto int_attr = [&](const char* name) {
      const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name);
      if (!a) throw Error(file, name, "missing int attribute");
      return a->value();
    };
    auto string_attr = [&](const char* name) {
      const auto* a = h.findTypedAttribute<Imf::StringAttribute>(name);
      if (!a) throw Error(file, name, "missing string attribute");
      return a->value();
    };

    const int version = int_attr("weft_format_version");
    if (version == 1 || version == 2)
      throw Error(file, "weft_format_version",
                  "is " + std::to_string(version) +
                      ": an octahedral-grid table whose bins straddle the horizon; re-bake it with "
                      "this version (format " +
                      std::to_string(kFormatVersion) + ")");
    if (version != kFormatVersion)
      throw Error(file, "weft_format_version",
                  "is " + std::to_string(version) + "; this program reads version " +
                      std::to_string(kFormatVersion));
    if (string_attr("parameterization") != kParameterization)
      throw Error(
          file, "parameterization",
          "is \"" + string_attr("parameterization") + "\", expected \"" + kParameterization + "\"");
    if (string_attr("units") != kUnits)
      throw Error(file, "units", "is \"" + string_attr("units") + "\", expected \"1/sr\"");
    table.kind = string_attr("kind");
    if (table.kind != "fiber" && table.kind != "fabric")
      throw Error(file, "kind", "must be \"fiber\" or \"fabric\", got \"" + table.kind + "\"");
    table.resolution = int_attr("resolution");
    if (table.resolution < 1 || table.resolution > kMaxResolution)
      throw Error(file, "resolution",
                  "must lie in [1, " + std::to_string(kMaxResolution) + "], got " +
                      std::to_string(table.resolution));
    const std::string bands = string_attr("bands");
    if (bands == "rgb") {
      table.channels = 3;
    } else if (bands == kSpectralBands) {
      table.channels = kNumBands;
    } else {
      throw Error(file, "bands", "must be \"rgb\" or \"390:710:10\", got \"" + bands + "\"");
    }

    const int n = table.bins();
    const Imath::Box2i dw = h.dataWindow();
    if (dw.min.x != 0 || dw.min.y != 0 || dw.max.x != n - 1 || dw.max.y != n - 1)
      throw Error(file, "dataWindow",
                  "must be " + std::to_string(n) + " x " + std::to_string(n) +
                      " pixels from (0, 0) for resolution " + std::to_string(table.resolution));

    const std::vector<std::string> names = table.channel_names();
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

    table.values.assign(static_cast<size_t>(n) * n * table.channels, 0.0f);
    Imf::FrameBuffer fb;
    const size_t x_stride = sizeof(float) * static_cast<size_t>(table.channels);
    const size_t y_stride = x_stride * static_cast<size_t>(n);
    char* base = reinterpret_cast<char*>(table.values.data());
    for (int c = 0; c < table.channels; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + sizeof(float) * c, x_stride, y_stride));
    const std::string stored_checksum = string_attr("values_fnv1a64");
    in.setFrameBuffer(fb);
    if (!in.isComplete()) throw Error(file, "", "truncated: pixel data incomplete");
    in.readPixels(0, n - 1);
    if (table.checksum() != stored_checksum)
      throw Error(file, "values_fnv1a64",
                  "pixel data is corrupt (checksum " + table.checksum() + " does not match " +
                      stored_checksum + ")");

    for (auto it = h.begin(); it != h.end(); ++it) {
      const std::string name = it.name();
      if (is_reserved_attribute(name)) continue;
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        table.metadata[name] = s->value();
    }
    if (string_attr("cell_average") != kCellAverage)
      throw Error(file, "cell_average",
                  "is \"" + string_attr("cell_average") + "\"; this program reads \"" +
                      kCellAverage + "\" cell averages");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("corrupt or truncated OpenEXR table: ") + e.what());
  }
  table.validate(file);
  return table;
}

}  // namespace weft
