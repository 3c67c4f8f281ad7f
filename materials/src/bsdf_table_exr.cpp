// OpenEXR reading and writing of TabulatedBsdfTable (format described in bsdf_table.h).
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <string>

#include "exr_io.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// The table's format from the header: version, parameterization, units, kind, resolution and
// bands (returned, as the file spells them).
std::string read_table_format(const Imf::Header& h, const std::string& file,
                              TabulatedBsdfTable& table) {
  using T = TabulatedBsdfTable;
  auto string_attr = [&](const char* name) { return exr_io::string_attribute(h, file, name); };
  const int version = exr_io::int_attribute(h, file, "weft_format_version");
  if (version == 1 || version == 2)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) +
                    ": an octahedral-grid table whose bins straddle the horizon; re-bake it with "
                    "this version (format " +
                    std::to_string(T::kFormatVersion) + ")");
  if (version < T::kOldestReadableVersion || version > T::kFormatVersion)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) + "; this program reads versions " +
                    std::to_string(T::kOldestReadableVersion) + " to " +
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
  table.resolution = exr_io::int_attribute(h, file, "resolution");
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
  exr_io::check_data_window(h, file, n, n, "resolution " + std::to_string(table.resolution));
  // The pixels must be in the file before their buffer is allocated.
  exr_io::check_fits_file(path, file, "resolution", double(n) * n * table.channels * sizeof(float),
                          std::to_string(table.resolution) + " and bands " + bands);
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
      Imf::Header header(bins(), bins());
      header.insert("weft_format_version", Imf::IntAttribute(kFormatVersion));
      header.insert("cell_average", Imf::StringAttribute(kCellAverage));
      header.insert("parameterization", Imf::StringAttribute(kParameterization));
      header.insert("resolution", Imf::IntAttribute(resolution));
      header.insert("bands", Imf::StringAttribute(bands()));
      header.insert("units", Imf::StringAttribute(kUnits));
      header.insert("kind", Imf::StringAttribute(kind));
      for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
      if (surface_lobe)
        for (const auto& [key, value] : surface_lobe->attributes())
          header.insert(key, Imf::StringAttribute(value));
      exr_io::write_image(tmp, header, channel_names(), values);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw Error(file, "", std::string("cannot write the OpenEXR table: ") + e.what());
    }
  });
}

TabulatedBsdfTable TabulatedBsdfTable::read_exr(const std::filesystem::path& path) {
  const std::string file = path.string();
  // The largest table: 2 R^2 bins a side.
  const int64_t max_bins = 2 * int64_t{kMaxResolution} * kMaxResolution;
  exr_io::check_magic(path, file);
  exr_io::check_header(path, file, max_bins, max_bins);

  TabulatedBsdfTable table;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    const std::string bands = read_table_format(h, file, table);
    check_pixel_size(h, path, file, table, bands);
    const std::vector<std::string> names = table.channel_names();
    exr_io::check_channels(h, file, names, bands);
    table.values = exr_io::read_pixels(in, file, names, table.bins(), table.bins());
    table.metadata = exr_io::string_attributes(h, is_reserved_attribute);
    // Version 3 knew no lobe: its attributes there would be metadata of another program's.
    if (exr_io::int_attribute(h, file, "weft_format_version") >= 4)
      table.surface_lobe = SurfaceLobe::from_attributes(
          exr_io::string_attributes(
              h, [](const std::string& n) { return !SurfaceLobe::is_attribute(n); }),
          table.channels, file);
    if (exr_io::string_attribute(h, file, "cell_average") != kCellAverage)
      throw Error(file, "cell_average",
                  "is \"" + exr_io::string_attribute(h, file, "cell_average") +
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